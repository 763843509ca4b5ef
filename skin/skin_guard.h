// Keeps the points of one strand out of the skin, point after point, with few closest-point queries.
// Used by fur and linear growth (each point kept out of the skin) and by the effects stack.
#pragma once

#include <Eigen/Core>
#include <algorithm>

#include "groom/mesh_query.h"
#include "skin/skin_grid.h"

namespace plume::skin {

/// The signed distance to a closed surface is 1-Lipschitz: sd(p) >= sd(q) - |p - q|. Knowing it at
/// the last queried point q, a point p with sd(q) - |p - q| >= margin is certainly outside by the
/// margin and needs no query. A strand rising from the skin is queried about log2(#points) times;
/// queries start from the last closest triangle (SkinGrid), so a strand lying along the skin is cheap,
/// and points far from every triangle of the grid are cleared without a query.
class SkinGuard {
 public:
  /// `scale`: a length of the scene (the mesh's size) for the absolute push tolerance.
  /// `grid` (may be null: whole-mesh queries only) must be built on the query's mesh.
  SkinGuard(const MeshQuery &query, float margin, float scale, const SkinGrid *grid = nullptr)
      : query_(query), grid_(grid), margin_(margin), overshoot_(1e-6f * scale + 1e-4f * std::max(margin, 0.0f)) {}

  /// Starts a strand at a point known to be on (or above) the skin.
  void start(const Eigen::Vector3f &on_skin, int triangle = -1) {
    known_point_ = on_skin;
    known_distance_ = 0.0f;
    hint_ = triangle;
  }
  /// Starts a strand at any point (one query), without moving it.
  void start_anywhere(const Eigen::Vector3f &p) {
    SurfacePoint closest;
    known_point_ = p;
    known_distance_ = query_.signed_distance(p, &closest);
    hint_ = closest.triangle;
  }

  /// Records that `p` is at least `lower_bound` (signed distance) from the skin, known without a
  /// query (e.g. from an earlier bound and how far p has moved since); the last closest triangle is
  /// kept as the next search's hint.
  void know(const Eigen::Vector3f &p, float lower_bound) {
    known_point_ = p;
    known_distance_ = lower_bound;
  }
  /// know(p, lower_bound) for a bound of at least the margin; true when p then needs no check
  /// (keep_out would leave it as it is without a query), false near an open edge of the mesh, where
  /// keep_out always queries.
  bool know_outside(const Eigen::Vector3f &p, float lower_bound) {
    know(p, lower_bound);
    return !(grid_ && grid_->near_open_edge(p));
  }
  /// A lower bound of the signed distance at `p` from what the guard knows (1-Lipschitz bound).
  float lower_bound(const Eigen::Vector3f &p) const { return known_distance_ - (p - known_point_).norm(); }
  /// The point the guard's bounds start from, and its signed distance or a lower bound of it.
  const Eigen::Vector3f &known_point() const { return known_point_; }
  float known_distance() const { return known_distance_; }

  /// Proves p outside by `radius` (at least the margin) without a distance query, and records it: no
  /// triangle lies within `radius` of p, and p cannot have crossed the skin since a point outside by
  /// at least `from_distance` (> 0) that is `moved` away (along that way the distance stays above
  /// (from_distance + radius - moved) / 2 > 0). False, recording nothing, when that is not shown, or
  /// p is near an open edge of the mesh.
  bool clear_by_ball(const Eigen::Vector3f &p, float radius, float from_distance, float moved) {
    if (!grid_ || radius < margin_ || !(from_distance > 0.0f) || !(from_distance + radius > moved) ||
        grid_->near_open_edge(p) || !grid_->clear_within(p, radius))
      return false;
    known_point_ = p;
    known_distance_ = radius;
    return true;
  }

  /// Moves `p` out along the surface normal if its signed distance is below the margin (a few
  /// iterations for concave places, where one move along the normal falls short). `always_query`
  /// skips the bounds: for a point placed just after a push, next to the skin, where the bounds
  /// would rarely clear it and where skin that overlaps itself (lips pressed together: two closed
  /// parts crossing) can change the side of a point without a crossing.
  /// Points near an open edge of the mesh (SkinGrid::near_open_edge) are always queried too.
  void keep_out(Eigen::Vector3f &p, bool always_query = false) {
    if (always_query || (grid_ && grid_->near_open_edge(p))) {
      query_and_push(p);
      return;
    }
    const float moved = (p - known_point_).norm();
    if (known_distance_ - moved >= margin_) return;
    // Far from every triangle (grid bound) and no way to have crossed the skin since the last known
    // outside point: along q -> p the distance stays above (sd(q) + lower - moved) / 2 > 0.
    auto clears = [&](float lower) { return lower >= margin_ && known_distance_ > 0.0f && known_distance_ + lower > moved; };
    float lower = grid_ ? grid_->distance_lower_bound(p) : 0.0f;
    if (grid_ && !clears(lower)) lower = std::max(lower, grid_->block_lower_bound(p));
    if (clears(lower)) {
      known_point_ = p;
      known_distance_ = lower;
      return;
    }
    // Only "p is outside by the margin" is needed, not p's distance (clear_by_ball). Twice the least
    // radius that can prove it leaves some room for the next points.
    if (clear_by_ball(p, 2.0f * std::max(margin_, moved - known_distance_), known_distance_, moved)) return;
    SurfacePoint closest;
    float distance = 0.0f;
    if (grid_) {
      // A search of the cells next to p is exact, or proves p at least `distance` from the skin: then,
      // as above, p is outside by the margin if it cannot have crossed since the last known point.
      if (!grid_->local_signed_distance(p, hint_, distance, closest)) {
        if (clears(distance)) {
          hint_ = closest.triangle;
          known_point_ = p;
          known_distance_ = distance;
          return;
        }
        distance = query_.signed_distance(p, &closest);
      }
    } else {
      distance = query_.signed_distance(p, &closest);
    }
    push_out(p, distance, closest);
  }

 private:
  /// An exact query at p, then the push.
  void query_and_push(Eigen::Vector3f &p) {
    SurfacePoint closest;
    const float distance = distance_to_skin(p, hint_, closest);
    push_out(p, distance, closest);
  }
  /// Pushes p (at signed `distance`, closest point `closest`) out to the margin and records it.
  void push_out(Eigen::Vector3f &p, float distance, SurfacePoint &closest) {
    for (int iteration = 0; iteration < 4 && distance < margin_; ++iteration) {
      p += (margin_ - distance + overshoot_) * surface_normal(query_.mesh(), closest);
      distance = distance_to_skin(p, closest.triangle, closest);
    }
    if (distance < 0.0f && known_distance_ >= 0.0f) {
      // Still inside (a fold where the normals lead back in, as between an ear and the head): keep
      // the farthest point outside on the way from the last known outside point, by bisection.
      const Eigen::Vector3f from = known_point_, to = p;
      float outside = 0.0f, inside = 1.0f;
      for (int iteration = 0; iteration < 16; ++iteration) {
        const float t = 0.5f * (outside + inside);
        SurfacePoint probe;
        if (distance_to_skin(from + t * (to - from), hint_, probe) >= 0.0f)
          outside = t;
        else
          inside = t;
      }
      p = from + outside * (to - from);
      distance = distance_to_skin(p, hint_, closest);
      if (distance < 0.0f) {
        p = from;
        distance = known_distance_;
      }
    }
    hint_ = closest.triangle;
    known_point_ = p;
    known_distance_ = distance;
  }

  const MeshQuery &query_;
  float distance_to_skin(const Eigen::Vector3f &p, int hint, SurfacePoint &r_closest) const {
    return grid_ ? grid_->signed_distance(p, hint, r_closest) : query_.signed_distance(p, &r_closest);
  }

  const SkinGrid *grid_;
  int hint_ = -1;  // the last closest triangle: bounds the next search
  float margin_;
  float overshoot_;
  Eigen::Vector3f known_point_ = Eigen::Vector3f::Zero();
  float known_distance_ = 0.0f;
};

/// Diagonal of the bounding box of a mesh's vertices.
inline float mesh_scale(const Mesh &mesh) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (const Eigen::Vector3f &p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return mesh.positions.empty() ? 0.0f : (hi - lo).norm();
}

}  // namespace plume::skin
