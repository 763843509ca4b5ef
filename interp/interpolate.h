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
/// and used slots come first, ordered by decreasing weight.
struct Binding {
  int k = 0;
  /// #roots * k guide indices into the guides given to bind(), -1 = unused slot.
  std::vector<int32_t> guide_ids;
  /// #roots * k rest-pose weights (distance falloff times parting factors), summing to 1 per root.
  std::vector<float> weights;
  /// #roots * k scale of each guide's 1/d law during streamline growth: the parting factor times a
  /// fade that reaches 0 as the guide becomes the (k+1)-th nearest, so that weights[i] is
  /// proportional to influence[i] / rest_distance[i]^falloff.
  std::vector<float> influence;
  /// #roots * k rotations, expressed from the guide root's surface frame to the root's surface frame
  /// at rest: Q_root(rest)^T * M * Q_guide(rest), M the minimal rotation taking the guide root's
  /// normal to the root's normal. At frame t the guide is carried by Q_root(t) * this * Q_guide(t)^T,
  /// which is exactly M under a rigid motion, whatever the frames' tangents.
  std::vector<Eigen::Quaternionf> rest_rotations;
  /// #roots target strand length (scene units): the weighted rest lengths of the root's guides.
  std::vector<float> lengths;
  /// #guides surface points of the guide roots (copied from Guides::roots), for the per-frame frames.
  std::vector<SurfacePoint> guide_roots;
  InterpolationSettings settings;
  /// The skin margin growth keeps (scene units): settings.skin_margin, or when that is negative
  /// (automatic) default_margin_fraction x the rest guides' median segment length.
  float skin_margin = 0.0f;

  size_t root_count() const { return lengths.size(); }
};

/// Binds every root to its k nearest guide roots (Euclidean distance on the rest pose, within
/// settings.radius when > 0; a root with no guide in the radius takes its nearest guide), restricted
/// to the guides of the root's hard zone and weighted by the partial partings when `partings` is
/// given (may be null). Weights fall off as 1/d^falloff (fur, linear) or 1/d (streamline, the law
/// that keeps the ratio of distances), faded to 0 at the (k+1)-th guide so they are continuous over
/// the surface; a guide root at distance ~0 takes all the weight.
/// Throws InputError for k outside [1, max_guides_per_root], no guides, or a zone with roots and no guide.
Binding bind(const Mesh &rest_mesh, const Guides &guides, const Roots &roots, const InterpolationSettings &settings,
             const PartingField *partings = nullptr);

/// How streamline growth took its steps, summed over the strands of one grow() call: the cost of a
/// groom in field evaluations, and where it went.
struct GrowStats {
  int64_t steps = 0;             // segments grown through the field (all but each strand's first)
  int64_t predicted_steps = 0;   // of those, taken with one field evaluation (a predicted midpoint)
  int64_t substepped_steps = 0;  // of those, split into substeps near a guide
  int64_t evaluations = 0;       // field evaluations (each searches every influencing guide)
  int64_t first_points = 0;      // strands' first points after the root (one per strand)
  int64_t first_points_proven = 0;  // of those, proven outside from earlier strands, with no skin search

  /// "1.092 field evaluations per step; steps predicted 94.4%, split near a guide 0.39%; first points
  /// proven from earlier strands 71.9%".
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
  /// When set, streamline growth fills it (fur and linear leave it zero).
  GrowStats *r_stats = nullptr;
};

/// Grows every root for one frame with binding.settings.method:
/// - fur: each guide carried to the root by its rotation, segment lengths and directions blended;
/// - linear: root-relative offsets of the guides blended, no rotation (a baseline: it crosses);
/// - streamline: streamline-ratio growth, skin push-out after each step.
/// `mesh` is the emitter posed at this frame (normals computed) and `query` is built on it; `guides`
/// holds the guide strands at this frame (same count and order as at binding; any point counts >= 2).
/// Output: r_strands gets roots.size() strands of options.points_per_strand points, ids = roots.ids.
/// Runs in parallel (OpenMP, static schedule); the output is identical for any thread count and
/// never holds NaN. Throws InputError when the roots or guides do not match the binding.
/// `r_clearance` (may be null): streamline growth fills it with one lower bound per output point of
/// that point's signed distance to the skin (what the skin push-out proved, at no extra cost), so
/// later passes that move points by less than that need no query; fur and linear leave it empty.
/// Every method keeps the points after the root out of the skin, at least binding.skin_margin
/// outside (fur and linear move a point that falls inside out to the margin).
/// `skin_grid` (may be null): a SkinGrid built on `mesh` and `query` this frame, to share with the
/// effects stack; when null, growth builds its own.
void grow(const Binding &binding, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
          const StrandSet &guides, const GrowOptions &options, StrandSet &r_strands,
          std::vector<float> *r_clearance = nullptr, const SkinGrid *skin_grid = nullptr);

/// Pushes points out of the skin: a point whose signed distance is below `margin` (scene units)
/// moves out along the surface normal at its closest point until it is at least ~margin outside.
/// The first point of every strand (its root) is kept. Parallel, thread-count independent.
void push_out_of_skin(const MeshQuery &query, float margin, StrandSet &r_strands);

}  // namespace plume::interp
