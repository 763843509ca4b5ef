// The separation pass: streamline strands are integral curves of one field, which never meet, but
// the polylines written at the groom's point count can, where the field brings neighbours closer than
// the chords' sag. This pass moves the written points of such pairs apart, each to the side its exact
// (finely integrated) curve is on. docs/interpolation.md, "Bunching" and "What is guaranteed".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "groom/mesh.h"

namespace plume::skin {
class SkinGrid;  // skin/skin_grid.h
}

namespace plume::interp {

/// The exact curves of a set of strands: fine polylines (the integration's accepted points), the
/// points of curve i being points[offsets[i] .. offsets[i + 1]], and each curve's length as cut
/// (the written strand's vertex j lies at arc length cut * j / (n - 1) along it).
struct ExactCurves {
  std::vector<size_t> offsets;  // #strands + 1
  std::vector<Eigen::Vector3f> points;
  std::vector<float> cuts;  // #strands
};

/// Distances of the pass, as multiples of the checker's default crossing tolerance (a thousandth of
/// the strands' median segment).
inline constexpr float separation_detect = 2.0f;  // pairs nearer than this are moved apart...
inline constexpr float separation_goal = 5.0f;    // ... to at least this along their exact side
/// Segment pairs at an angle below this (degrees) are left alone (the checker's transversal angle
/// is 10 degrees; nearly parallel strands lying on each other are touching, not crossing).
inline constexpr float separation_angle_degrees = 6.0f;
/// A point of a strand at a guide root (which reproduces its guide within 0.1% of its length) is
/// moved by at most this fraction of the strands' median segment in all (20 times the checker's
/// tolerance)...
inline constexpr float separation_largest_move_at_guide = 0.02f;
/// ... any other point by at most this fraction of its own strand's segment (its written length over
/// n - 1), and never more than this fraction of the median segment nor less than the one above.
inline constexpr float separation_largest_move = 0.1f;

/// What the pass did.
struct SeparationStats {
  int64_t pairs_found = 0;   // segment pairs within separation_detect at the first sweep
  int64_t pairs_left = 0;    // segment pairs still within the checker's tolerance after the last sweep
  int64_t points_moved = 0;  // written points moved (each counted once)
  int64_t undecided = 0;     // pushes whose exact curves were themselves too close to tell a side (looked
                             // at on a pair's first push, and again where its segments meet in parallel)
  int64_t slid = 0;          // moves near the skin that lost their part into it
  int64_t retracted = 0;     // tips moved back along their own last segment (a tip at the skin)
  int searches = 0;          // searches for pairs: the first over all segments, then again from the
                             // segments that moved since the last, when a point has drifted far
  int sweeps = 0;
  float largest_move = 0.0f;  // the largest distance a point moved, in scene units
};

/// Moves the points of `strand_count` strands of `n` points each (`positions`, #strands * n, root
/// first) so that no two segments of different strands at an angle above separation_angle_degrees
/// are nearer than separation_detect times `tolerance`: each such pair is pushed apart to
/// separation_goal times `tolerance` along the direction from the other strand's exact curve to its
/// own (their closest points within one segment of the meeting), so the written polylines keep the
/// sides their curves have, and a planar set of strands stays in its plane. Roots never move; a point
/// is moved only where its signed distance to the skin stays at least min(margin, its bound) (the
/// bound, `lower`, #strands * n, is lowered by the move, or set from a query), and at most its
/// strand's largest move: separation_largest_move_at_guide of the median segment for a strand flagged
/// in `at_guide_root` (#strands, or empty: none), else separation_largest_move of its own segment
/// within those bounds. A tip that cannot move aside (a strand ended at the skin) may move back along
/// its own last segment instead. Sweeps until no pair is left (at most a fixed number). Sequential over
/// sorted pairs: the same result for any thread count.
SeparationStats separate_strands(std::span<Eigen::Vector3f> positions, int n, const ExactCurves &curves,
                                 float tolerance, float margin, const Mesh &mesh, const skin::SkinGrid &skin_grid,
                                 std::span<float> lower, std::span<const uint8_t> at_guide_root = {});

}  // namespace plume::interp
