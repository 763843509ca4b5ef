// The velocity field that interpolated strands follow: at every point of space, the tangents of the
// guides blended by their distances (Hair Designer's ratio-of-distances law), a function of position
// only, continuous and Lipschitz, and on each guide that guide's own tangent. Maths and guarantees:
// docs/interpolation.md, "The field".
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "groom/strand_set.h"

namespace plume::interp {

/// How the guides' tangents are blended. `reach` and `coil_reach` are ratios of distances (no unit);
/// `floor` is a length (scene units).
struct FieldShape {
  /// A guide at distance d weighs 1/d, faded smoothly to 0 as d goes from (reach - 1) to reach times
  /// (d_min + floor), d_min the distance of the nearest guide: influence stays local (a far guide
  /// never bends a strand) and a guide's entry is gradual.
  float reach = 3.0f;
  /// Scene units, >= 0. Without it, near a guide the others fade out within a tube about a quarter of
  /// the gap to them, where the field is that guide's tangent alone; strands drawn towards the guide
  /// by the others slow down at the tube's wall and pile up on it, far closer than their roots (the
  /// polylines written then cross). With it, the guides within reach times the floor keep weighing
  /// down to the guide itself (1/d still dominates there, so the guide stays an integral curve), and
  /// the blend narrows the gap between neighbours smoothly instead. Growth sets it to one length unit.
  float floor = 0.0f;
  /// The floor at x is min(floor, floor_slope * d_min): within floor / floor_slope of a guide it
  /// shrinks to 0 on the guide, so there the others count only within reach (1 + floor_slope) d_min
  /// and, nearer still, the guide alone steers. Without that thin tube a guide among guides that
  /// diverge from it repels the strands near it at a rate of their divergence over their distance,
  /// and a strand at the guide's root, a rounding error away from it, drifts off (0.35% of the
  /// length on a random flow, against the 0.1% promised). At 10, a tube of a tenth of the floor, one
  /// pair crossed at 11 degrees in a small proxy of Sintel, as without a tube; at 3, none.
  float floor_slope = 3.0f;
  /// Along one guide, each piece's tangent (at x's projection on its chord) counts with a weight that
  /// fades from 1 when the piece's chord is as near as the guide's nearest chord to 0 when it is
  /// `coil_reach` times farther: two
  /// coils of a curl at nearly the same distance share the guide's tangent, so it never jumps from
  /// one coil to the other.
  float coil_reach = 1.25f;
};

/// One piece of a guide: the cubic Hermite curve between two consecutive guide points,
/// c(t) = a + b t + c t^2 + d t^3 for t in [0, 1], with the guide's unit tangent at both ends times
/// the chord's length as end derivatives. Consecutive pieces share their end point and tangent
/// direction: each guide is a C1 curve through its points (tangent directions continuous).
struct GuidePiece {
  Eigen::Vector3f a, b, c, d;  // power basis
  Eigen::Vector3f centre;      // a ball holding the piece: centre and radius
  float radius = 0.0f;
  /// A capsule holding the piece: its chord (from a, `chord` long along unit `axis`) thickened by
  /// `sag`, the farthest Bezier control point from the chord.
  Eigen::Vector3f axis = Eigen::Vector3f::UnitX();
  float chord = 0.0f;
  float sag = 0.0f;
  int32_t guide = 0;           // index into the guides the field was built from
};

/// Scales guides' influence at one point of space (partial partings, docs/interpolation.md): an
/// attenuated guide counts as if it were 1 / factor times farther.
class GuideAttenuation {
 public:
  virtual ~GuideAttenuation() = default;
  /// In [0, 1]; 1 leaves the guide as it is.
  virtual float factor(int32_t guide) const = 0;
};

class GuideField {
 public:
  /// `guides`: the guides at this frame (any point counts >= 2, finite); `members`: the indices of
  /// the guides this field blends (one hard zone), ascending; `cell`: the search grid's cell size
  /// (scene units, > 0; about a guide segment). The field keeps no reference to `guides`.
  GuideField(const StrandSet &guides, std::span<const int32_t> members, const FieldShape &shape, float cell);

  /// The pieces that can matter anywhere within `valid` of `centre`: of the guides that can weigh
  /// there, the pieces that can be their nearest or take a share of their tangent. Evaluating with
  /// them gives the same answer as with every piece (see evaluate()).
  struct Candidates {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    float valid = -1.0f;          // nothing listed yet
    std::vector<int32_t> pieces;  // ascending
    std::vector<float> piece_lower;  // per listed piece, a lower bound of its distance at `centre`
    /// The listed guides, ascending, each with its pieces' range in `pieces` and, at `centre`, lower
    /// and upper bounds of its distance.
    struct Guide {
      int32_t guide, begin, end;
      float lower, upper;
    };
    std::vector<Guide> guides;
  };

  /// One thread's scratch for evaluate(), and the candidates of the last point evaluated outside the
  /// field's shared cells (kept from one evaluation to the next). It never changes an answer.
  struct Cache {
    Candidates own;
    /// The listed pieces' distance bounds, and the closest points computed.
    struct Near {
      int32_t piece;
      float lower;           // a lower bound of the piece's distance (its capsule's)
      float distance;        // the exact distance, or infinity when not computed
      float chord_distance;  // the distance to the piece's chord
    };
    std::vector<Near> near;  // slots; an evaluation uses a prefix
    /// Per measured guide: its pieces' range in `near` and its slot of least bound, its distance, its
    /// effective distance and its pieces' least chord distance.
    struct Group {
      int32_t guide;
      size_t begin, end, best;
      float distance, counted, chord_min;
    };
    std::vector<Group> groups;
    std::vector<int32_t> order;
    std::vector<float> lowers;  // per piece, scratch for gathering and narrowing lists
    std::vector<float> distances;  // per span, for gathering lists
    /// One guide's listed pieces' bounds and chord distances.
    std::vector<float> measured_lower, measured_chord;
    /// Pieces whose exact distances are computed together, and their slots; then the pieces with a
    /// share in their guide's tangent.
    std::vector<int32_t> ids;
    std::vector<size_t> slots;
    std::vector<float> distances_out;
    /// Per weighing guide, its weight and its pieces with a share: their range in `ids`, and per
    /// piece its fade argument, its share and its unit tangent.
    struct Weighing {
      float weight;
      size_t begin, end;
    };
    std::vector<Weighing> weighing;
    std::vector<float> fractions, shares, unit_x, unit_y, unit_z;
    /// A shared list being made: its vectors keep their capacity, and the list published is an
    /// exact-size copy.
    Candidates making;
  };

  struct Sample {
    /// The blend of the guides' unit tangents, sum_g w_g T_g / sum_g w_g, of length <= 1 (shorter
    /// where the guides disagree; zero only where they cancel).
    Eigen::Vector3f direction = Eigen::Vector3f::Zero();
    /// Distance to the nearest guide (scene units); infinity when the field has no guide.
    float nearest = INFINITY;
  };
  /// The field at x: w_g = fade(d_g / (d_min + h) - (reach - 1)) / d_g, h = min(floor, floor_slope
  /// d_min), with d_g the distance from x to guide g's curve and d_min the nearest guide's; T_g the
  /// tangent of guide g at its nearest pieces (see FieldShape::coil_reach); on a guide (d_g within a
  /// millionth of a cell), that guide's tangent.
  /// Thread-safe (the cache is the caller's; the shared cells are filled once each, whichever thread
  /// comes first, with lists that depend on the cell alone).
  /// `attenuation` (may be null): factors for the guides at x; a guide at distance d then counts
  /// at d / factor (a factor of 0 removes it, except on the guide itself).
  Sample evaluate(const Eigen::Vector3f &x, Cache &cache, const GuideAttenuation *attenuation = nullptr) const;

  bool empty() const { return pieces_.empty(); }

  GuideField(const GuideField &) = delete;
  GuideField &operator=(const GuideField &) = delete;
  ~GuideField();

 private:
  /// Lists the candidates within `valid` of x (valid < 0: max(U / 2, half a cell), U an upper bound
  /// of the nearest guide's distance at x). `found`, `lowers` and `distances` are scratch.
  void gather(const Eigen::Vector3f &x, float valid, Candidates &r_candidates, std::vector<int32_t> &found,
              std::vector<float> &lowers, std::vector<float> &distances) const;
  /// The capsule bounds at x of `pieces` (`count` indices) into r_lowers and, when r_chords is not
  /// null, the distances to their chords (each bound plus its sag) into r_chords.
  void piece_lowers(const Eigen::Vector3f &x, const int32_t *pieces, size_t count, float *r_lowers,
                    float *r_chords = nullptr) const;
  /// The exact distances from x to `pieces` (`count` indices) into r_distances, as distance_to_piece.
  void piece_distances(const Eigen::Vector3f &x, const int32_t *pieces, size_t count, float *r_distances) const;
  /// Per piece j of `pieces` (`count` indices): its share fade(fractions[j]) into r_shares and its
  /// unit tangent T_j into r_x, r_y, r_z (each array holding `count` rounded up to the lanes). T_j is
  /// the tangent at the parameter of x's projection on the piece's chord, t0 = clamp((x - a) . axis
  /// / chord, 0, 1): continuous in x, equal to the guide's tangent at the piece's ends, and within
  /// about theta^3 / 24 of the tangent at the closest point for a piece turning by theta.
  void piece_tangents(const Eigen::Vector3f &x, const int32_t *pieces, const float *fractions, size_t count,
                      float *r_shares, float *r_x, float *r_y, float *r_z) const;
  /// Per span, the distance from x to its ball's centre; returns the least distance plus radius.
  float span_distances(const Eigen::Vector3f &x, std::vector<float> &r_distances) const;
  /// Appends, ascending, the spans whose ball's bound (distance less radius) is within `radius`.
  void spans_within(const std::vector<float> &distances, float radius, std::vector<int32_t> &r_found) const;
  /// The shared candidates of the cell holding x, listed on first use; null when x lies outside
  /// the shared cells.
  const Candidates *shared_candidates(const Eigen::Vector3f &x, Cache &cache) const;
  /// Lists the candidates within `valid` of x from `from`, a list valid over a ball that holds
  /// that one. `lowers` is scratch.
  void narrow(const Candidates &from, const Eigen::Vector3f &x, float valid, Candidates &r_list,
              std::vector<float> &lowers) const;
  /// Publishes an exact-size copy of `made` into a shared slot unless another thread did first;
  /// returns the slot's list.
  static const Candidates *publish(std::atomic<Candidates *> &slot, const Candidates &made);
  Eigen::Vector3i cell_of(const Eigen::Vector3f &p) const;
  size_t cell_index(int x, int y, int z) const {
    return (size_t(z) * size_t(dims_.y()) + size_t(y)) * size_t(dims_.x()) + size_t(x);
  }

  FieldShape shape_;
  std::vector<GuidePiece> pieces_;  // grouped by guide, in guide order, each guide's in order
  /// Per piece, its capsule and its ball (copies of GuidePiece's), packed for the bounds' loops.
  struct Capsule {
    float ax, ay, az, ux, uy, uz, chord, sag;  // a, axis, chord, sag
  };
  struct Ball {
    Eigen::Vector3f centre;
    float radius;
  };
  std::vector<Capsule> capsules_;
  /// Per piece, its cubic (GuidePiece's a, b, c, d), axis and chord, packed for the lanes' loops.
  struct Cubic {
    float ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, ux, uy, uz, chord;
  };
  std::vector<Cubic> cubics_;
  std::vector<Ball> balls_;
  float cell_ = 1.0f;
  float max_sag_ = 0.0f;  // the largest piece's sag
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  /// A run of consecutive pieces [begin, end) of one guide, in a ball holding the pieces' balls.
  struct PieceSpan {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    float radius = 0.0f;
    int32_t guide = 0, begin = 0, end = 0;
  };
  std::vector<PieceSpan> spans_;  // grouped by guide, in guide order
  std::vector<float> span_x_, span_y_, span_z_, span_radius_;  // the spans' balls, packed
  std::vector<int32_t> cell_offsets_;  // CSR over cells: spans whose ball's box meets the cell
  std::vector<int32_t> cell_spans_;
  /// Per guide index (of the guides given): its pieces' range in pieces_ (empty for a non-member).
  std::vector<int32_t> guide_begin_, guide_end_;
  /// Per guide index: its spans' range in spans_.
  std::vector<int32_t> guide_span_begin_, guide_span_end_;
  /// The shared cells: a uniform grid of half the search cell over the guides' box and two search
  /// cells round it, each cell's candidates (for its centre, valid over the whole cell) listed by
  /// the first evaluation inside it and shared by every strand and thread from then on.
  float shared_cell_ = 1.0f;
  Eigen::Vector3f shared_origin_ = Eigen::Vector3f::Zero();
  Eigen::Vector3i shared_dims_ = Eigen::Vector3i::Zero();
  std::unique_ptr<std::atomic<Candidates *>[]> shared_;
  /// Parent cells of twice the edge (2 x 2 x 2 shared cells each), whose lists, gathered from the
  /// search grid, the shared cells' lists are narrowed from.
  Eigen::Vector3i parent_dims_ = Eigen::Vector3i::Zero();
  std::unique_ptr<std::atomic<Candidates *>[]> parents_;
};

/// Smooth step from 1 (u <= 0) to 0 (u >= 1): 1 - 3u^2 + 2u^3 in between (C1).
inline float fade(float u) {
  if (u <= 0.0f) return 1.0f;
  if (u >= 1.0f) return 0.0f;
  return 1.0f - u * u * (3.0f - 2.0f * u);
}

}  // namespace plume::interp
