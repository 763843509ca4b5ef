// One frame of feathers as the outputs hold them: curves (rachis and barbs) and vane meshes, flat
// arrays as StrandSet keeps strands. feathers/ fills them; io/ writes them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "groom/strand_set.h"

namespace plume {

/// What a curve of a feather is (written per curve as `feather_part`).
enum class FeatherPart : uint8_t {
  rachis = 0,
  left_barb = 1,
  right_barb = 2,
  after_rachis = 3,
  after_left_barb = 4,
  after_right_barb = 5,
};

/// Feathers as curves. Each feather's curves are consecutive: its rachis (with the calamus), its
/// barbs, then its afterfeather's.
struct FeatherCurves {
  /// The curves, widths set; ids are the feathers' stable ids (every curve of a feather carries its
  /// feather's id).
  StrandSet curves;
  std::vector<FeatherPart> parts;        // one per curve
  std::vector<int32_t> templates;        // one per curve: the feather's main template (index)
  std::vector<uint32_t> feathers;        // one per curve: the feather's index in its coat
  /// Texture coordinates, one per point: along the barb (u from the rachis to the tip, v the barb's
  /// place on the rachis) and across the vane (the flat feather).
  std::vector<Eigen::Vector2f> uv_barb, uv_vane;
};

/// Vanes as triangle meshes. Each feather's vertices and triangles are consecutive.
struct VaneMesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector2f> uv_barb, uv_vane;  // one per vertex, as FeatherCurves's
  std::vector<Eigen::Vector3i> triangles;         // indices into positions
  std::vector<uint64_t> triangle_feathers;        // one per triangle: its feather's stable id
  std::vector<int32_t> triangle_templates;        // one per triangle: its feather's main template
};

}  // namespace plume
