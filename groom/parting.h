// Partings: hard zones that split the emitter, and partial parting lines drawn on the surface
// (Hair Designer, "Partings", Figure 5).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "groom/error.h"

namespace plume {

/// A polyline of points on (or near: they are snapped) the emitter. A partial parting need not
/// cross the whole surface; a root C and a guide root H get the guide weight multiplied by
/// (D / D1)^gamma, D the geodesic C-H distance, D1 the shortest path that does not cross the line.
struct PartingLine {
  std::string name;
  std::vector<Eigen::Vector3f> points;  // rest-pose positions, in order
  bool closed = false;                  // a closed loop
  float gamma = 2.0f;                   // >= 1
  /// When true the line is a hard cut: it splits the surface into zones (with closed lines or lines
  /// that reach the mesh border); when false it is a partial parting that only attenuates weights.
  bool hard = false;
  FileLoc loc;
};

struct PartingSettings {
  enum class ZoneSource { none, face_groups, zone_map, lines };
  ZoneSource zone_source = ZoneSource::none;
  /// For face_groups: which groups are zones (empty: every group is its own zone).
  std::vector<std::string> zone_groups;
  /// Where partings.zones.groups is written, for messages (empty when not given).
  FileLoc zone_groups_loc;
  /// For zone_map: a text file with one integer zone id per triangle (path resolved against the groom).
  std::string zone_map_path;
  std::vector<PartingLine> lines;
  FileLoc loc;
};

}  // namespace plume
