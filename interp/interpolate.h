// Interpolation: turns a few guide strands into dense strands. bind() runs once on the rest pose
// (which guides influence each root, with which weights); grow() runs every frame. Methods and maths:
// docs/interpolation.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/strand_set.h"

namespace plume::skin {
class SkinGrid;  // skin/skin_grid.h
}
namespace plume::partings {
class PartingField;  // partings/parting_field.h
}

namespace plume::interp {

using partings::PartingField;
using skin::SkinGrid;

/// Which guides influence each root and how much; computed once on the rest pose. Arrays marked
/// "#roots * k" hold slot s of root r at index r * k + s; unused slots have guide id -1 and weight 0,
/// and used slots come first, ordered by decreasing weight. Fur and linear blend these slots;
/// streamline growth follows the field of the guides (interp/guide_field.h) and takes from the
/// binding only each strand's length and root lift.
struct Binding {
  int k = 0;
  /// #roots * k guide indices into the guides given to bind(), -1 = unused slot.
  std::vector<int32_t> guide_ids;
  /// #roots * k rest-pose weights (distance falloff times parting factors), summing to 1 per root.
  std::vector<float> weights;
  /// #roots * k rotations, expressed from the guide root's surface frame to the root's surface frame
  /// at rest: Q_root(rest)^T * M * Q_guide(rest), M the minimal rotation taking the guide root's
  /// normal to the root's normal. At frame t the guide is carried by Q_root(t) * this * Q_guide(t)^T,
  /// which is exactly M under a rigid motion, whatever the frames' tangents.
  std::vector<Eigen::Quaternionf> rest_rotations;
  /// #roots target strand length (scene units): the weighted rest lengths of the root's guides.
  std::vector<float> lengths;
  /// #guides surface points of the guide roots (copied from Guides::roots), for the per-frame frames.
  std::vector<SurfacePoint> guide_roots;
  /// Hard zones: #roots and #guides zone indices in [0, zone_count) (all 0 without zones). A strand
  /// follows the field of its zone's guides alone.
  int zone_count = 1;
  std::vector<int32_t> root_zones;
  std::vector<int32_t> guide_zones;
  /// The groom's length unit (scene units): the median length of the rest guides' segments. Every
  /// default length of growth is a fraction of it, so a groom behaves the same at any scale.
  float length_unit = 0.0f;
  /// #roots: 1 where the root is at a guide root (a hit: within root_hit_of_diagonal times the rest
  /// emitter's bounding-box diagonal of it at rest, at most root_hit_of_length_unit times the length
  /// unit), else 0. Only the guides hit weigh, and a streamline strand there follows the guide's own
  /// curve from its own root.
  std::vector<uint8_t> hits;
  /// The skin margin (scene units): settings.skin_margin, or when that is negative (the default)
  /// default_margin_fraction * length_unit. Strands keep at least this far from the skin.
  float skin_margin = 0.0f;
  /// Streamline growth's longest integration step (scene units): step_fraction * length_unit.
  float step = 0.0f;
  /// Streamline growth's error allowed per step (scene units): tolerance_fraction * length_unit.
  float tolerance = 0.0f;
  /// The partings the binding was made with (null: none); not owned, and must outlive the binding.
  /// Streamline growth attenuates guides across partial lines with it (docs/interpolation.md).
  const PartingField *partings = nullptr;
  InterpolationSettings settings;

  size_t root_count() const { return lengths.size(); }
};

/// A root within this fraction of the rest emitter's bounding-box diagonal of a guide root is at
/// that guide root: twice the checker's root tolerance (plume check judges strands whose roots lie
/// within 1e-4 of the posed emitter's diagonal of a guide root against that guide), so that every
/// strand the checker holds to its guide is grown as the guide, on any pose.
inline constexpr float root_hit_of_diagonal = 2e-4f;
/// ... and never more than this fraction of the groom's length unit.
inline constexpr float root_hit_of_length_unit = 0.05f;
/// The skin margin's default, as a fraction of the groom's length unit (Binding::length_unit).
inline constexpr float default_margin_fraction = 0.1f;
/// Streamline growth's longest step, as a fraction of the length unit: one guide segment.
inline constexpr float step_fraction = 1.0f;
/// Streamline growth's error per step, as a fraction of the length unit.
inline constexpr float tolerance_fraction = 1e-2f;
/// Nearer the guides the error allowed per step is at most this fraction of the nearest guide's
/// distance (and at least a hundredth of the tolerance).
inline constexpr float tolerance_per_distance = 1e-3f;
/// A streamline strand ends where the field, bent by the skin band, is shorter than this (its guides'
/// tangents cancel, or the skin leaves no way along it): there the unit direction V / |V| is no
/// longer Lipschitz, and strands arriving from two sides would meet head on (docs/interpolation.md,
/// "Where a strand ends early"). Within twice the skin margin the length needed falls linearly to
/// 0.4 of this on the skin, below the band's lift, so that no strand ends at its root.
inline constexpr float min_field_length = 0.5f;
/// The skin band's depth, in skin margins (docs/interpolation.md, "The skin"): streamline growth
/// takes away the inward part of the field below it, fully at one margin. The checker holds strands
/// at guide roots to their guide only where the guide stays above it.
inline constexpr float skin_band_margins = 2.0f;
/// The field's grid cell, in length units; a guide point within a millionth of it of the previous
/// one is left out of the guide's curve.
inline constexpr float field_cell_fraction = 2.0f;

/// Binds every root to its k nearest guide roots (Euclidean distance on the rest pose, within
/// settings.radius when > 0; a root with no guide in the radius takes its nearest guide), restricted
/// to the guides of the root's hard zone and weighted by the partial partings when `partings` is
/// given (may be null). Weights fall off as 1/d^falloff (fur, linear) or 1/d (streamline, the law
/// that keeps the ratio of distances), faded to 0 at the (k+1)-th guide so they are continuous over
/// the surface; a guide root at distance ~0 takes all the weight.
/// Throws InputError for k outside [1, max_guides_per_root], no guides, or a zone with roots and no guide.
Binding bind(const Mesh &rest_mesh, const Guides &guides, const Roots &roots, const InterpolationSettings &settings,
             const PartingField *partings = nullptr);

/// What growth did, summed over the strands of one grow() call: its cost, and how often its safety
/// nets acted (both should stay at 0: they mean the field led a step into the skin).
struct GrowStats {
  int64_t steps = 0;         // accepted integration steps (streamline) or walked sub-steps (fur, linear)
  int64_t rejected_steps = 0;  // streamline: steps redone shorter, their error above the tolerance
  int64_t evaluations = 0;   // field evaluations (streamline)
  int64_t skin_queries = 0;  // exact signed-distance queries in the skin band
  int64_t halved_steps = 0;  // steps retried at half length because they ended inside the skin
  int64_t short_strands = 0; // strands that stalled before their length (the field vanished)
  int64_t ended_strands = 0; // of those, strands ended where the bent field was below min_field_length
  // Streamline's separation pass (interp/separate.h), over the whole grow() call:
  int64_t separated_pairs = 0;    // segment pairs of different strands found too near at first
  int64_t unseparated_pairs = 0;  // segment pairs still within the checker's default tolerance after it
  int64_t separation_points_moved = 0;
  int separation_sweeps = 0;
  float separation_largest_move = 0.0f;  // scene units

  /// "4.02 field evaluations per step, 0.31 skin queries per step; 0 steps halved, 0 strands short".
  std::string summary() const;
  /// Adds another part's counts (a thread's) to these.
  GrowStats &operator+=(const GrowStats &other);
};

struct GrowOptions {
  /// Points per output strand, >= 2 (the root is the first point).
  int points_per_strand = 32;
  /// Strand diameter at the root and at the tip (scene units), linear in between.
  float width_root = 0.02f;
  float width_tip = 0.005f;
  bool with_widths = true;
  /// When set, growth fills it.
  GrowStats *r_stats = nullptr;
  /// Streamline: move written points apart where the polylines of neighbouring strands meet
  /// (interp/separate.h). Off by default: with it, a strand's written points depend (by at most
  /// the pass's largest move) on the strands grown with it, so a proxy is no longer an exact subset
  /// of a larger run (docs/interpolation.md, "What is guaranteed").
  bool separate = false;
};

/// Grows every root for one frame with binding.settings.method:
/// - streamline: each strand is the integral curve, from its root, of the field of its zone's
///   guides at this frame (interp/guide_field.h), bent away from the skin within a band of twice the
///   margin, integrated with error-controlled steps (at most binding.step) and cut at its length, then resampled by arc
///   length;
/// - fur: each guide carried to the root by its rotation, segment lengths and directions blended;
/// - linear: root-relative offsets of the guides blended, no rotation (a baseline: it crosses).
/// Fur and linear move a point that falls inside the skin (or within the margin) out to the margin,
/// so no method leaves a point inside the skin. `mesh` is the emitter posed at this frame (normals computed) and `query` is built
/// on it; `guides` holds the guide strands at this frame (same count and order as at binding; any
/// point counts >= 2).
/// Output: r_strands gets roots.size() strands of options.points_per_strand points, ids = roots.ids.
/// Runs in parallel (OpenMP); the output is identical for any thread count, a strand is the same
/// whichever other roots are grown with it, and it never holds NaN. Throws InputError when the roots
/// or guides do not match the binding.
/// `r_clearance` (may be null): filled with one lower bound per output point of that point's signed
/// distance to the skin (what growth proved on the way, at no extra cost), so later passes that move
/// points by less than that need no query.
/// `skin_grid` (may be null): a SkinGrid built on `mesh` and `query` this frame, to share with the
/// effects stack; when null, growth builds its own.
void grow(const Binding &binding, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
          const StrandSet &guides, const GrowOptions &options, StrandSet &r_strands,
          std::vector<float> *r_clearance = nullptr, const SkinGrid *skin_grid = nullptr);

/// The first point of each root's strand at this frame, as grow() writes it (any method; the
/// separation pass never moves it), without growing the strands: `plume check` finds a strand
/// file's roots among the groom's with it. Same inputs and errors as grow().
std::vector<Eigen::Vector3f> strand_starts(const Binding &binding, const Mesh &mesh, const MeshQuery &query,
                                           const Roots &roots, const StrandSet &guides,
                                           const SkinGrid *skin_grid = nullptr);

}  // namespace plume::interp
