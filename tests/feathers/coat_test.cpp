// A coat on the bird of grooms/bird/: feathers follow the skin rigidly under a rigid motion, never
// spin on a deforming skin, never go below it, come out the same for any thread count, keep their
// follicles when the count grows, scale with the groom, and blend key feathers continuously.
#include <catch2/catch.hpp>
#include <omp.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "feather_fixtures.h"
#include "feathers/coat.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "skin/skin_grid.h"

using namespace plume;
using namespace plume::feathers;

namespace {

/// The bird's coat without the pass that keeps feathers apart (layering_test.cpp): the coat's own promises.
struct Bird : test::BirdCoat {
  explicit Bird(int64_t follicles = -1, float scale = 1.0f) : BirdCoat(follicles, test::layers_off, scale) {}
};

/// Each feather's length: the arc length of its shaft (calamus and rachis).
std::vector<float> feather_lengths(const CoatFrame &frame, size_t feathers) {
  std::vector<float> length(feathers, 0.0f);
  const StrandSet &c = frame.curves.curves;
  for (size_t s = 0; s < c.strand_count(); ++s)
    if (frame.curves.parts[s] == FeatherPart::rachis) length[frame.curves.feathers[s]] = float(c.length(s));
  return length;
}

}  // namespace

TEST_CASE("the bird's coat: about 5,000 feathers of every key feather's type", "[feathers]") {
  const Bird bird;
  CHECK(bird.coat->size() >= 4800);
  CHECK(bird.coat->size() <= 5000);
  std::vector<int> per_template(bird.groom.feathers.templates.size(), 0);
  for (const int32_t t : bird.coat->templates()) ++per_template[size_t(t)];
  for (size_t t = 0; t < per_template.size(); ++t) {
    INFO(bird.groom.feathers.templates[t].name);
    CHECK(per_template[t] > 10);
  }
}

TEST_CASE("a rigid motion of the body moves every feather rigidly, to 2e-5 of its length", "[feathers]") {
  const Bird bird;
  const CoatFrame at_rest = bird.grow(bird.rest);
  for (const float angle : {0.7f, 2.5f}) {
    // About the bird's middle, then moved by its own size: coordinates keep their magnitude, so the
    // float positions of the moved skin are as precise as at rest (the frames at a follicle come
    // from the skin's edges, a few millimetres long).
    const Eigen::Vector3f centre(0.0f, 8.0f, -1.0f);
    const Eigen::Affine3f motion = Eigen::Translation3f(centre + Eigen::Vector3f(5.0f, -3.0f, 4.0f)) *
                                   Eigen::AngleAxisf(angle, Eigen::Vector3f(0.3f, 1.0f, -0.2f).normalized()) *
                                   Eigen::Translation3f(-centre);
    Mesh moved = bird.rest;
    for (Eigen::Vector3f &p : moved.positions) p = motion * p;
    moved.compute_normals();
    const CoatFrame frame = bird.grow(moved);
    const std::vector<float> sizes = feather_lengths(at_rest, bird.coat->size());
    const StrandSet &a = at_rest.curves.curves, &b = frame.curves.curves;
    REQUIRE(a.point_count() == b.point_count());
    std::vector<float> worst(bird.coat->size(), 0.0f);
    for (size_t s = 0; s < a.strand_count(); ++s)
      for (int64_t p = a.offsets[s]; p < a.offsets[s + 1]; ++p) {
        const float d = (motion * a.positions[size_t(p)] - b.positions[size_t(p)]).norm();
        float &w = worst[at_rest.curves.feathers[s]];
        w = std::max(w, d);
      }
    // A feather the skin pass does not lift is rigid to 2e-5 of its length (float rounding of the
    // moved skin and of its stems' carried points: 1.05e-5 at most over these two motions, since stems
    // are bound below their first points along the normal rather than at their closest points). One it lifts takes the
    // turn at which its worst sample clears the skin, which amplifies the rounding of the moved skin's
    // float coordinates (about 1e-6 here) by the inverse of the rate at which lifting raises that sample:
    // up to 5e-5 of its length where the sample lies near the root.
    size_t bad = 0, lifted_over = 0;
    float relative = 0.0f, relative_unlifted = 0.0f;
    for (size_t f = 0; f < worst.size(); ++f) {
      const float r = worst[f] / sizes[f];
      relative = std::max(relative, r);
      if (at_rest.lifts[f] == 0.0f && frame.lifts[f] == 0.0f) {
        relative_unlifted = std::max(relative_unlifted, r);
        if (r > 2e-5f) ++bad;
      } else if (r > 1e-5f) {
        ++lifted_over;
      }
    }
    INFO("largest departure from the rigid motion: " << relative << " of the feather's length ("
                                                     << relative_unlifted << " of feathers not lifted; "
                                                     << lifted_over << " lifted feathers beyond 1e-5)");
    CHECK(bad == 0);
    CHECK(relative <= 5e-5f);
    CHECK(lifted_over <= worst.size() / 20);
    // The vanes too.
    float vane_worst = 0.0f;
    for (size_t v = 0; v < at_rest.vanes.positions.size(); ++v)
      vane_worst = std::max(vane_worst, (motion * at_rest.vanes.positions[v] - frame.vanes.positions[v]).norm());
    CHECK(vane_worst <= 1e-5f * 14.0f);
  }
}

TEST_CASE("no feather spins when the skin deforms: its base frame turns only to lift it", "[feathers]") {
  // Measured from the output: each feather's base frame is the shaft (its calamus) and the first
  // segment of its left vane's first row, both fixed to the feather at its base. In the follicle's
  // skin frame, the rotation from the rest pose's base frame to a deformed pose's may only turn about
  // the horizontal axis across the shaft (the skin pass lifting the feather): the angle by which it
  // moves that axis is the spin, and the shaft's azimuth about the normal must not change either.
  // Bound: 1e-3 radians. Without dynamics, so that the stems only follow the skin.
  const Bird bird;
  auto bases = [&](const CoatFrame &frame) {
    std::vector<Eigen::Matrix3f> out(bird.coat->size());
    std::vector<Eigen::Vector3f> shaft(out.size()), across(out.size());
    const StrandSet &c = frame.curves.curves;
    for (size_t s = 0; s < c.strand_count(); ++s)
      if (frame.curves.parts[s] == FeatherPart::rachis) {
        const uint32_t f = frame.curves.feathers[s];
        shaft[f] = frame.root_frames[f].basis.transpose() * (c.points(s)[1] - c.points(s)[0]).normalized();
      }
    std::vector<bool> done(out.size(), false);
    std::map<uint64_t, size_t> index_of;
    for (size_t i = 0; i < bird.coat->size(); ++i) index_of[bird.coat->ids()[i]] = i;
    for (size_t t = 0; t < frame.vanes.triangles.size(); ++t) {
      const size_t f = index_of.at(frame.vanes.triangle_feathers[t]);
      if (done[f]) continue;
      done[f] = true;
      const Eigen::Vector3i &tri = frame.vanes.triangles[t];
      across[f] = frame.root_frames[f].basis.transpose() *
                  (frame.vanes.positions[size_t(tri[1])] - frame.vanes.positions[size_t(tri[0])]);
    }
    for (size_t f = 0; f < out.size(); ++f) {
      const Eigen::Vector3f x = (across[f] - across[f].dot(shaft[f]) * shaft[f]).normalized();
      out[f].col(0) = x;
      out[f].col(1) = shaft[f].cross(x);
      out[f].col(2) = shaft[f];
    }
    return out;
  };
  const std::vector<Eigen::Matrix3f> rest = bases(bird.grow(bird.rest));
  float worst_spin = 0.0f, worst_azimuth = 0.0f;
  for (const int frame_number : {5, 13, 25, 37, 48}) {
    const std::vector<Eigen::Matrix3f> posed = bases(bird.grow(bird.pose(frame_number)));
    for (size_t f = 0; f < rest.size(); ++f) {
      const Eigen::Vector3f shaft = rest[f].col(2);
      const Eigen::Vector3f lift_axis = Eigen::Vector3f::UnitZ().cross(shaft);
      if (lift_axis.norm() < 0.05f) continue;  // a feather standing along the normal has no such axis
      const Eigen::Matrix3f turn = posed[f] * rest[f].transpose();
      const Eigen::Vector3f a = lift_axis.normalized();
      worst_spin = std::max(worst_spin, std::acos(std::clamp((turn * a).dot(a), -1.0f, 1.0f)));
      const Eigen::Vector3f posed_shaft = posed[f].col(2);
      if (std::hypot(shaft.x(), shaft.y()) > 0.17f && std::hypot(posed_shaft.x(), posed_shaft.y()) > 0.17f) {
        float d = std::abs(std::atan2(shaft.y(), shaft.x()) - std::atan2(posed_shaft.y(), posed_shaft.x()));
        worst_azimuth = std::max(worst_azimuth, std::min(d, 2.0f * 3.14159265f - d));
      }
    }
  }
  INFO("largest spin " << worst_spin << " rad, largest change of the shaft's azimuth " << worst_azimuth << " rad");
  CHECK(worst_spin <= 1e-3f);
  CHECK(worst_azimuth <= 1e-3f);
}

TEST_CASE("no vane point below the skin, on every 4th frame of the bird's sequence", "[feathers]") {
  // The independent check: MeshQuery's signed distance (the coat's skin pass uses the skin grid), on
  // every curve point and vane vertex; a point counts as below past 1e-5 of the bird's size, the
  // checker's tolerance. The skin is closed, so the distance is 1-Lipschitz and a point can only get
  // below it by passing through it: a point nearer a queried point outside than that point's distance
  // is outside too (the segment between them never touches the skin), and is not queried. Points are
  // taken in runs of consecutive ones (a feather's), each run from its last queried point.
  const Bird bird;
  const float eps = 1e-5f * 40.0f;
  size_t checked = 0, queried = 0;
  const auto count_below = [&](const MeshQuery &query, const std::vector<Eigen::Vector3f> &points, size_t &r_below,
                               float &r_deepest) {
    constexpr int64_t run = 256;
    const int64_t runs = (int64_t(points.size()) + run - 1) / run;
    size_t below = 0, asked = 0;
    float deepest = 0.0f;
#pragma omp parallel for schedule(static) reduction(+ : below, asked) reduction(min : deepest)
    for (int64_t r = 0; r < runs; ++r) {
      Eigen::Vector3f known = Eigen::Vector3f::Zero();
      float known_distance = -1.0f;  // none yet
      for (int64_t p = r * run; p < std::min(int64_t(points.size()), (r + 1) * run); ++p) {
        const Eigen::Vector3f &x = points[size_t(p)];
        if (known_distance > 0.0f && (x - known).norm() < known_distance) continue;  // outside, as argued
        const float d = query.signed_distance(x);
        ++asked;
        if (d < -eps) ++below;
        deepest = std::min(deepest, d);
        known = x;
        known_distance = d;
      }
    }
    r_below += below;
    r_deepest = std::min(r_deepest, deepest);
    queried += asked;
  };
  for (int frame_number = 1; frame_number <= 48; frame_number += 4) {
    const Mesh posed = bird.pose(frame_number);
    const MeshQuery query(posed);
    REQUIRE(query.open_edges().empty());  // the argument above needs a closed skin
    const CoatFrame frame = bird.grow(posed);
    size_t below = 0;
    float deepest = 0.0f;
    count_below(query, frame.curves.curves.positions, below, deepest);
    count_below(query, frame.vanes.positions, below, deepest);
    checked += frame.curves.curves.positions.size() + frame.vanes.positions.size();
    INFO("frame " << frame_number << ": deepest " << deepest);
    CHECK(below == 0);
  }
  CHECK(checked > 10'000'000);
  WARN(queried << " of " << checked << " points queried");
}

TEST_CASE("a coat's frame is the same to the bit for 1 and 2 threads", "[feathers]") {
  const Bird bird(1500);
  const Mesh posed = bird.pose(20);
  omp_set_num_threads(1);
  const CoatFrame one = bird.grow(posed);
  omp_set_num_threads(2);
  const CoatFrame two = bird.grow(posed);
  CHECK(one.curves.curves.positions == two.curves.curves.positions);
  CHECK(one.curves.curves.widths == two.curves.curves.widths);
  CHECK(one.vanes.positions == two.vanes.positions);
  CHECK(one.lifts == two.lifts);
}

TEST_CASE("more follicles keep every feather of fewer", "[feathers]") {
  const Bird few(800), many(2000);
  const CoatFrame a = few.grow(few.rest), b = many.grow(many.rest);
  // Every follicle of the smaller coat is in the larger one, and its feather is the same.
  std::map<uint64_t, size_t> index_of;
  for (size_t i = 0; i < many.coat->size(); ++i) index_of[many.coat->ids()[i]] = i;
  auto curves_of = [](const CoatFrame &frame, uint32_t feather) {
    std::vector<Eigen::Vector3f> points;
    const StrandSet &c = frame.curves.curves;
    for (size_t s = 0; s < c.strand_count(); ++s)
      if (frame.curves.feathers[s] == feather) points.insert(points.end(), c.points(s).begin(), c.points(s).end());
    return points;
  };
  size_t same = 0;
  for (size_t i = 0; i < few.coat->size(); i += 37) {
    const auto at = index_of.find(few.coat->ids()[i]);
    REQUIRE(at != index_of.end());
    // The stems and key feathers are the same, so is the feather (the lift depends on the skin only).
    if (curves_of(a, uint32_t(i)) == curves_of(b, uint32_t(at->second))) ++same;
  }
  CHECK(same == (few.coat->size() + 36) / 37);
}

TEST_CASE("a groom scaled to millimetres grows the same feathers, scaled", "[feathers]") {
  const Bird cm(600), mm(600, 10.0f);
  const CoatFrame a = cm.grow(cm.rest), b = mm.grow(mm.rest);
  REQUIRE(a.curves.curves.point_count() == b.curves.curves.point_count());
  float worst = 0.0f;
  for (size_t p = 0; p < a.curves.curves.point_count(); ++p)
    worst = std::max(worst, (10.0f * a.curves.curves.positions[p] - b.curves.curves.positions[p]).norm());
  // Relative to the bird's size (400 mm).
  CHECK(worst <= 2e-4f * 400.0f);
  CHECK(a.lifts.size() == b.lifts.size());
}

TEST_CASE("key-feather weights are continuous over the surface", "[feathers]") {
  const Bird bird(10);
  const KeyFeatherField field(bird.rest, bird.groom.feathers);
  const size_t keys = field.key_count();
  // Pairs of points a small step apart across every edge of a sample of triangles: the weights of
  // the two points (in the two triangles) differ by at most a Lipschitz bound times the step.
  size_t pairs = 0;
  float worst_rate = 0.0f;
  std::vector<float> wa(keys), wb(keys);
  const std::vector<uint32_t> welded = welded_vertices(bird.rest, weld_distance(bird.rest));
  // Triangles sharing an edge (over welded vertices).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<int>> faces_of_edge;
  for (size_t f = 0; f < bird.rest.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = welded[size_t(bird.rest.triangles[f][k])], b = welded[size_t(bird.rest.triangles[f][(k + 1) % 3])];
      faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(int(f));
    }
  for (const auto &[edge, faces] : faces_of_edge) {
    if (faces.size() != 2) continue;
    // The edge's midpoint seen from each face: the same point, two barycentric descriptions.
    auto on_face = [&](int f, float t) {
      SurfacePoint sp;
      sp.triangle = f;
      sp.bary = Eigen::Vector3f::Zero();
      const Eigen::Vector3i &tri = bird.rest.triangles[size_t(f)];
      for (int k = 0; k < 3; ++k) {
        if (welded[size_t(tri[k])] == edge.first) sp.bary[k] += 1.0f - t;
        if (welded[size_t(tri[k])] == edge.second) sp.bary[k] += t;
      }
      return sp;
    };
    for (const float t : {0.25f, 0.5f}) {
      field.weights(on_face(faces[0], t), wa);
      field.weights(on_face(faces[1], t), wb);
      for (size_t k = 0; k < keys; ++k) worst_rate = std::max(worst_rate, std::abs(wa[k] - wb[k]));
    }
    ++pairs;
  }
  // The same point through two faces gets the same weights: the field is continuous across edges.
  CHECK(pairs > 1000);
  CHECK(worst_rate <= 1e-5f);
  // And along the surface: points 1 mm apart inside a face change by little.
  float worst_step = 0.0f;
  for (size_t f = 0; f < bird.rest.triangle_count(); f += 7) {
    SurfacePoint a, b;
    a.triangle = b.triangle = int(f);
    a.bary = Eigen::Vector3f(0.4f, 0.3f, 0.3f);
    b.bary = Eigen::Vector3f(0.3f, 0.4f, 0.3f);
    const float step = (surface_position(bird.rest, a) - surface_position(bird.rest, b)).norm();
    field.weights(a, wa);
    field.weights(b, wb);
    for (size_t k = 0; k < keys; ++k) worst_step = std::max(worst_step, std::abs(wa[k] - wb[k]) / std::max(step, 1e-6f));
  }
  // The kernel exp(-(d/r)^2) changes by at most ~0.86 / r per unit of distance (r >= 1 here), and the
  // normalisation by at most twice that.
  CHECK(worst_step <= 2.0f);
}
