// A feather's output geometry at a level of detail: its curves (rachis with calamus, barbs,
// afterfeather) and its vane meshes, evaluated from the Bezier curves into caller-owned arrays and
// mapped from feather space to the world through the shaft's pose. No allocation.
#pragma once

#include <Eigen/Core>
#include <array>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "feathers/feather.h"
#include "groom/feather_frame.h"
#include "groom/strand_set.h"

namespace plume::feathers {

/// How much one feather outputs at a level of detail. Curves come in this order: the rachis (the
/// calamus base, then rachis_points points from the calamus top to the tip), the left barbs, the
/// right barbs (barb_points points each, in rachis order), then the afterfeather's rachis
/// (rachis_points) and barbs. Vane meshes: left, right, then the afterfeather's left and right, each
/// vane_rows x (vane_columns + 1) vertices and (vane_rows - 1) x vane_columns x 2 triangles.
struct FeatherCounts {
  int64_t curves = 0;
  int64_t points = 0;
  int64_t vane_vertices = 0;
  int64_t vane_triangles = 0;
};
FeatherCounts feather_counts(const FeatherShape &shape, const FeatherDetail &detail);

/// The pose of the shaft at height z: a point of a part attached there goes from feather space to
/// the world as origin + rotation * (p - (0, 0, z)).
struct ShaftPose {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
};

/// The identity: feather space is the world.
struct FlatShaft {
  ShaftPose operator()(float z) const { return {Eigen::Vector3f(0.0f, 0.0f, z), Eigen::Matrix3f::Identity()}; }
};

/// Arrays for one feather's curves, starting at its first point (and first curve). Texture
/// coordinates (sec. 4.3.3): `uv_barb` along each barb (u from 0 at the rachis to 1 at the tip, v
/// the barb's place on the rachis; the rachis has u = 0) and `uv_vane` across the vane (the flat
/// feather, rachis straight: u = 0.5 + x / L, v = z / L, L the shaft's length), both ignoring the
/// rachis curvature so a texture stays with the feather. Any pointer may be null.
struct CurvesOut {
  Eigen::Vector3f *positions = nullptr;
  float *widths = nullptr;
  Eigen::Vector2f *uv_barb = nullptr;
  Eigen::Vector2f *uv_vane = nullptr;
  FeatherPart *parts = nullptr;  // one per curve
  /// Added to every point as it is written (a feather's root): the feather is computed near the
  /// origin and placed with one rounding, so its shape does not depend on where it is.
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
};

/// Arrays for one feather's vane meshes. Triangle indices are relative to the feather's first
/// vertex plus `first_vertex`. Triangles face dorsally (counter-clockwise seen from above the vane).
struct VanesOut {
  Eigen::Vector3f *positions = nullptr;
  Eigen::Vector2f *uv_barb = nullptr;
  Eigen::Vector2f *uv_vane = nullptr;
  Eigen::Vector3i *triangles = nullptr;
  int64_t first_vertex = 0;
  /// Added to every vertex as it is written (as CurvesOut::offset).
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
};

namespace detail {

/// The Bernstein weights of one degree at a barb's even parameters u_j = j / (point_count - 1), a
/// block of points at a time, kept while the barbs that follow have the same degree and point count
/// (those of a vane mostly do). Computed per point right before the sums that read them, the weights'
/// loads waited on their stores (a sixth of the time spent writing barbs).
class BernsteinBlock {
 public:
  /// The weights B^(count-1)_i(u_j), i < count, for point j of a barb of point_count points.
  const float *at(int count, int point_count, int j) {
    if (count != count_ || point_count != point_count_ || j < first_ || j >= first_ + kPoints) {
      count_ = count;
      point_count_ = point_count;
      first_ = j - j % kPoints;
      for (int k = first_; k < std::min(point_count, first_ + kPoints); ++k)
        bernstein_weights(count - 1, float(k) / float(point_count - 1), weights_[size_t(k - first_)].data());
    }
    return weights_[size_t(j - first_)].data();
  }

 private:
  static constexpr int kPoints = 32;
  int count_ = -1, point_count_ = -1, first_ = 0;
  std::array<std::array<float, max_barb_control_points>, kPoints> weights_;
};

/// One barb's points into the arrays: barb_points samples of its Bezier curve at even parameters.
/// `pose` is the shaft's at the barb's attachment, barb.attach + offset.
inline void emit_barb(const Barb &barb, const Eigen::Vector3f &offset, const ShaftPose &pose, int point_count,
                      float barb_width, float rp, float flat_length, const Eigen::Vector3f &placed_at,
                      BernsteinBlock &bernstein, Eigen::Vector3f *r_positions, float *r_widths,
                      Eigen::Vector2f *r_uv_barb, Eigen::Vector2f *r_uv_vane) {
  const Eigen::Vector3f attach = barb.attach + offset;
  // The polygon goes to the world first (Bezier curves are affine invariant), then is sampled.
  const Eigen::Matrix3f to_world = pose.rotation * barb.frame;
  const Eigen::Vector3f base = pose.origin + pose.rotation * Eigen::Vector3f(attach.x(), attach.y(), 0.0f);
  ControlPolygon world;
  world.count = barb.polygon.count;
  for (int i = 0; i < world.count; ++i) world.points[size_t(i)] = base + to_world * barb.polygon.points[size_t(i)];
  for (int j = 0; j < point_count; ++j) {
    const float u = float(j) / float(point_count - 1);
    const float *weights = bernstein.at(world.count, point_count, j);
    Eigen::Vector3f p = Eigen::Vector3f::Zero();
    Eigen::Vector3f local = Eigen::Vector3f::Zero();
    for (int i = 0; i < world.count; ++i) {
      p += weights[i] * world.points[size_t(i)];
      local += weights[i] * barb.polygon.points[size_t(i)];
    }
    r_positions[j] = placed_at + p;
    if (r_widths) r_widths[j] = barb_width * (1.0f - 0.75f * u);
    if (r_uv_barb) r_uv_barb[j] = Eigen::Vector2f(u, rp);
    if (r_uv_vane) {
      const Eigen::Vector3f flat = barb.attach_flat + barb.frame_flat * local;
      r_uv_vane[j] = Eigen::Vector2f(0.5f + flat.x() / flat_length, flat.z() / flat_length);
    }
  }
}

/// One part (the main feather or the afterfeather): rachis then barbs, or its two vane meshes.
template <class Pose>
void emit_part_curves(const FeatherShape &shape, bool after, const FeatherDetail &detail, const Pose &pose_at,
                      const CurvesOut &out, int64_t &r_point, int64_t &r_curve) {
  const FeatherTemplate &f = after ? shape.after : shape.main;
  const Eigen::Vector3f offset = after ? afterfeather_offset(shape.main) : Eigen::Vector3f::Zero();
  const float flat_length = std::max(f.calamus_length + f.rachis_length, 1e-30f);
  // The rachis: the calamus base (main feather only), then rachis_points along the Bezier.
  if (out.parts) out.parts[r_curve] = after ? FeatherPart::after_rachis : FeatherPart::rachis;
  ++r_curve;
  auto rachis_sample = [&](const Eigen::Vector3f &p_feather, float z_own, float v) {
    const Eigen::Vector3f p = p_feather + offset;
    const ShaftPose pose = pose_at(p.z());
    if (out.positions)
      out.positions[r_point] = out.offset + (pose.origin + pose.rotation * Eigen::Vector3f(p.x(), p.y(), 0.0f));
    if (out.widths) out.widths[r_point] = shaft_width(f, z_own);
    if (out.uv_barb) out.uv_barb[r_point] = Eigen::Vector2f(0.0f, v);
    if (out.uv_vane) out.uv_vane[r_point] = Eigen::Vector2f(0.5f, z_own / flat_length);
    ++r_point;
  };
  if (!after) rachis_sample(Eigen::Vector3f::Zero(), 0.0f, 0.0f);
  for (int i = 0; i < detail.rachis_points; ++i) {
    const float t = float(i) / float(detail.rachis_points - 1);
    rachis_sample(rachis_point(f, t), f.calamus_length + f.rachis_length * t, t);
  }
  // The left barbs, then the right ones; computed a position at a time, as both barbs there leave
  // the rachis at one point and frame, and follow one shaft pose.
  const std::vector<float> &positions = after ? shape.after_positions : shape.main_positions;
  const int64_t count = int64_t(positions.size());
  const std::array<std::vector<KeyBarb>, 2> &keys = after ? shape.after_keys : shape.main_keys;
  const uint64_t seed = after ? ~shape.seed : shape.seed;
  std::array<VaneBarbs, 2> barbs = {VaneBarbs(f, keys[0], Vane::left, seed), VaneBarbs(f, keys[1], Vane::right, seed)};
  std::array<BernsteinBlock, 2> bernstein;  // per vane
  for (int64_t j = 0; j < count; ++j) {
    const float rp = positions[size_t(j)];
    const BarbAttachment attachment = barb_attachment(f, rp);
    const ShaftPose pose = pose_at(attachment.point.z() + offset.z());
    for (const Vane vane : {Vane::left, Vane::right}) {
      const Barb barb = barbs[size_t(vane)](rp, int(j), attachment);
      const int64_t curve = r_curve + int64_t(vane) * count + j, point = r_point + (curve - r_curve) * detail.barb_points;
      emit_barb(barb, offset, pose, detail.barb_points, f.barb_width, rp, flat_length, out.offset, bernstein[size_t(vane)],
                out.positions ? out.positions + point : nullptr, out.widths ? out.widths + point : nullptr,
                out.uv_barb ? out.uv_barb + point : nullptr, out.uv_vane ? out.uv_vane + point : nullptr);
      if (out.parts)
        out.parts[curve] = after ? (vane == Vane::left ? FeatherPart::after_left_barb : FeatherPart::after_right_barb)
                                 : (vane == Vane::left ? FeatherPart::left_barb : FeatherPart::right_barb);
    }
  }
  r_point += 2 * count * detail.barb_points;
  r_curve += 2 * count;
}

template <class Pose>
void emit_part_vanes(const FeatherShape &shape, bool after, const FeatherDetail &detail, const Pose &pose_at,
                     const VanesOut &out, int64_t &r_vertex, int64_t &r_triangle) {
  const FeatherTemplate &f = after ? shape.after : shape.main;
  const Eigen::Vector3f offset = after ? afterfeather_offset(shape.main) : Eigen::Vector3f::Zero();
  const float flat_length = std::max(f.calamus_length + f.rachis_length, 1e-30f);
  const int rows = detail.vane_rows, columns = detail.vane_columns;
  BernsteinBlock bernstein;
  for (const Vane vane : {Vane::left, Vane::right}) {
    VaneBarbs barbs(f, (after ? shape.after_keys : shape.main_keys)[size_t(vane)], vane, shape.seed);
    const int64_t first = r_vertex;
    for (int r = 0; r < rows; ++r) {
      const float rp = float(r) / float(rows - 1);
      const Barb barb = barbs(rp, -1, barb_attachment(f, rp));
      emit_barb(barb, offset, pose_at(barb.attach.z() + offset.z()), columns + 1, 0.0f, rp, flat_length, out.offset,
                bernstein, out.positions ? out.positions + r_vertex : nullptr, nullptr,
                out.uv_barb ? out.uv_barb + r_vertex : nullptr, out.uv_vane ? out.uv_vane + r_vertex : nullptr);
      r_vertex += columns + 1;
    }
    if (!out.triangles) {
      r_triangle += int64_t(rows - 1) * columns * 2;
      continue;
    }
    // Vertex (r, c) is row r (along the rachis), column c (along the barb). The right vane's columns
    // run toward +x, the left's toward -x: the windings differ so both face dorsally.
    for (int r = 0; r + 1 < rows; ++r)
      for (int c = 0; c < columns; ++c) {
        const int64_t base = out.first_vertex + first;
        const int v00 = int(base + int64_t(r) * (columns + 1) + c), v01 = v00 + 1;
        const int v10 = v00 + columns + 1, v11 = v10 + 1;
        if (vane == Vane::left) {
          out.triangles[r_triangle++] = Eigen::Vector3i(v00, v01, v11);
          out.triangles[r_triangle++] = Eigen::Vector3i(v00, v11, v10);
        } else {
          out.triangles[r_triangle++] = Eigen::Vector3i(v00, v11, v01);
          out.triangles[r_triangle++] = Eigen::Vector3i(v00, v10, v11);
        }
      }
  }
}

}  // namespace detail

/// Writes one feather's curves (feather_counts(...).curves curves and .points points) into `out`,
/// each feather-space point p of a part attached at height z placed at pose_at(z).origin +
/// pose_at(z).rotation * (p - (0, 0, z)): barbs follow the shaft's pose at their attachment, rigidly.
template <class Pose>
void emit_curves(const FeatherShape &shape, const FeatherDetail &detail, const Pose &pose_at, const CurvesOut &out) {
  int64_t point = 0, curve = 0;
  detail::emit_part_curves(shape, false, detail, pose_at, out, point, curve);
  if (shape.has_after) detail::emit_part_curves(shape, true, detail, pose_at, out, point, curve);
}

/// Writes one feather's vane meshes into `out` (feather_counts(...).vane_vertices and
/// .vane_triangles), placed as emit_curves() places points. Rows sample barbs evenly along the
/// rachis; plumulaceous barbs take their mean shape (a card shows no fuzz).
template <class Pose>
void emit_vanes(const FeatherShape &shape, const FeatherDetail &detail, const Pose &pose_at, const VanesOut &out) {
  int64_t vertex = 0, triangle = 0;
  detail::emit_part_vanes(shape, false, detail, pose_at, out, vertex, triangle);
  if (shape.has_after) detail::emit_part_vanes(shape, true, detail, pose_at, out, vertex, triangle);
}

/// One feather in feather space, allocated: for tests, pictures and single-feather tools.
struct FeatherGeometry {
  StrandSet curves;                    // widths set; ids 0 .. curves - 1
  std::vector<FeatherPart> parts;      // one per curve
  std::vector<Eigen::Vector2f> uv_barb, uv_vane;  // one per point
  std::vector<Eigen::Vector3f> vane_positions;
  std::vector<Eigen::Vector2f> vane_uv_barb, vane_uv_vane;
  std::vector<Eigen::Vector3i> vane_triangles;
};
FeatherGeometry build_feather(const FeatherShape &shape, const FeatherDetail &detail);

}  // namespace plume::feathers
