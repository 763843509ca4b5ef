// A guide's curve: the C1 curve through its points that the field growth follows, and against which
// the checker measures the strands rooted at guide roots.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

namespace plume {

class MeshQuery;

/// One piece of a guide's curve: the cubic Hermite curve between two consecutive distinct guide
/// points, c(t) = a + b t + c t^2 + d t^3 for t in [0, 1], with the guide's unit tangent at both ends
/// times the chord's length as end derivatives.
struct CurvePiece {
  Eigen::Vector3f a, b, c, d;  // power basis
  Eigen::Vector3f end;         // the next guide point (c(1) up to rounding)
  Eigen::Vector3f at(float t) const { return a + t * (b + t * (c + t * d)); }
  Eigen::Vector3f derivative(float t) const { return b + t * (2.0f * c + 3.0f * t * d); }
};

/// Guide points closer to the previous one than this fraction of the groom's length unit (its
/// median guide segment) are one point of the curve: growth, binding and the checker all use it.
inline constexpr float curve_merge_fraction = 2e-6f;

/// The curve through `points`: their distinct points (a point within `tiny` of the previous one is
/// left out) joined by Hermite cubics. Unit tangents at inner points bisect the two chords meeting
/// there; at the ends, the inner tangent mirrored about the end chord (exact on a circular arc).
/// Consecutive pieces share their end point and tangent direction (C1 in direction). Fewer than two
/// distinct points give no piece. r_pieces is cleared first.
void guide_curve(std::span<const Eigen::Vector3f> points, float tiny, std::vector<CurvePiece> &r_pieces);

/// The arc length of the pieces (8-point Gauss-Legendre per piece: exact to rounding on pieces as
/// smooth as these).
double curve_length(std::span<const CurvePiece> pieces);

/// The curve at `per_piece` evenly spaced parameters per piece, and its last point.
std::vector<Eigen::Vector3f> sample_curve(std::span<const CurvePiece> pieces, int per_piece);

/// Samples per piece at which a guide's curve is followed and judged (growth's strands at guide
/// roots, the checker's deviation and its low-guide rule): one sampling, so both see the same curve.
inline constexpr int guide_curve_samples_per_piece = 16;

/// Whether a guide's curve, sampled from its root (`samples`, e.g. sample_curve's), runs low: goes
/// into the skin past its root, or comes back below `band` (the skin band of the growth) once risen
/// to it (a guide rooted on the skin starts in the band). There the skin promise wins over following
/// the guide: growth grows such a strand from the field, and the checker counts it apart. Fills
/// r_distances, when given, with the samples' signed distances (up to the first low one).
bool guide_runs_low(std::span<const Eigen::Vector3f> samples, const MeshQuery &query, float band,
                    std::vector<float> *r_distances = nullptr);

}  // namespace plume
