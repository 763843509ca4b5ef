// How feathers move between two frames and how far they stray from their template: popping (the
// largest jump of a feather's vane vertices in its follicle's skin frame, in rachis widths) and shape
// drift (the vane's distance from its template after the best rigid fit, in % of the feather's
// length). Used by `plume check --previous` and the tests. Rules: docs/check.md, "Feathers".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>

#include "groom/mesh.h"

namespace plume::check {

struct Popping {
  /// The largest jump of a vane vertex between the frames, in its follicle's skin frame, divided by
  /// its feather's rachis width; its feather's id and the jump in scene units.
  double largest = 0.0;
  double largest_distance = 0.0;
  uint64_t worst_feather = 0;
  /// The mean over feathers of each feather's largest jump, in rachis widths.
  double mean = 0.0;
  int64_t feathers = 0;
};

/// Feather f's vane vertices are [first_vertex[f], first_vertex[f + 1]) of both `previous` and
/// `current` (the same layout in both frames, world or object space of each frame); `previous_frames`
/// and `current_frames` are its follicle's skin frames at each (origin on the skin); `rachis_widths`
/// its rachis width (scene units, > 0); `ids` its stable id.
Popping popping(std::span<const Eigen::Vector3f> previous, std::span<const Eigen::Vector3f> current,
                std::span<const int64_t> first_vertex, std::span<const SurfaceFrame> previous_frames,
                std::span<const SurfaceFrame> current_frames, std::span<const float> rachis_widths,
                std::span<const uint64_t> ids);

struct ShapeDrift {
  /// Per feather, the largest distance of a vane vertex from its template's after the rotation and
  /// translation that fit the template to it best (least squares, Kabsch), as a fraction of the
  /// feather's length: the mean over feathers and the largest, with its feather's id.
  double mean = 0.0;
  double largest = 0.0;
  uint64_t worst_feather = 0;
  int64_t feathers = 0;
};

/// `positions` and `template_positions` share the layout of `first_vertex` (as popping);
/// `lengths` are the feathers' lengths (scene units, > 0).
ShapeDrift shape_drift(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3f> template_positions,
                       std::span<const int64_t> first_vertex, std::span<const float> lengths,
                       std::span<const uint64_t> ids);

}  // namespace plume::check
