// Partings on the emitter, built once on the rest pose: hard zones (a root only sees the guides of
// its own zone) and partial parting lines that attenuate a guide's weight by (D / D1)^gamma
// (Hair Designer, "Partings", Figure 5). See docs/partings.md for the geodesic method.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/parting.h"

namespace plume::partings {

class PartingField {
 public:
  /// Builds zones (face groups, a zone map file, or hard lines cutting the surface) and, for every
  /// partial line, one geodesic distance field per guide on the intact mesh and one on the mesh cut
  /// open along the line. `rest_mesh` and `guides` are only read during construction.
  /// Throws InputError (with the setting's FileLoc) for an unknown group, an unreadable or
  /// malformed zone map (file:line), a hard line that separates nothing, or gamma < 1.
  PartingField(const Mesh &rest_mesh, const Guides &guides, const PartingSettings &settings);
  ~PartingField();
  PartingField(PartingField &&) noexcept;
  PartingField &operator=(PartingField &&) noexcept;

  /// No zones and no partial lines: weight_factor() is always 1.
  bool empty() const;
  /// Number of hard zones (1 when there are none).
  int zone_count() const;
  /// Zone of the triangle holding `p`, in [0, zone_count()); 0 when there are no zones.
  int zone_of(const SurfacePoint &p) const;
  /// Zone of a guide's root.
  int guide_zone(size_t guide) const;
  /// Human-readable zone name for messages: the face group, "zone map id N", or the region of a
  /// hard line.
  const std::string &zone_name(int zone) const;
  /// Throws InputError naming the zone when one of `roots` lies in a zone that holds no guide.
  void check_roots_have_guides(std::span<const SurfacePoint> roots) const;

  /// Multiplier of guide `guide`'s weight for a root at `root`: 0 when they are in different hard
  /// zones, else the product over partial lines of (D / D1)^gamma, in (0, 1]. It is 0 too when a
  /// "partial" line in fact separates root and guide completely (D1 infinite). Thread-safe.
  float weight_factor(const SurfacePoint &root, size_t guide) const;
  /// Geodesic distance (scene units) from a guide's root to `root` on the intact mesh (D), and on
  /// the mesh cut open along partial line `line` (D1, index into the partial lines in settings
  /// order); infinity when unreachable. Exposed for tests and diagnostics.
  float geodesic_distance(const SurfacePoint &root, size_t guide) const;
  float detour_distance(const SurfacePoint &root, size_t guide, size_t line) const;
  size_t partial_line_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plume::partings
