// The feather checker's order and motion measures on hand-made vanes whose answer is known: a
// planted order violation is found (and not when the order agrees), the skin stops the way out, a
// swapped pair is an order flip, a planted pop is measured in rachis widths, a rigid move of skin and
// feathers together is no pop, and shape drift ignores rigid motion but measures a shrunk feather. Every case
// again at scales 1e-3 and 1e3 (no absolute unit).
#include <catch2/catch.hpp>

#include <cmath>

#include "check/feather_layers.h"
#include "check/feather_motion.h"
#include "groom/mesh_query.h"

using namespace plume;
using Eigen::Vector3f;

namespace {

/// Vane meshes built feather by feather, as feathers/ lays them out.
struct Vanes {
  std::vector<Vector3f> positions;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<uint64_t> ids;
  std::vector<int64_t> first_vertex{0};

  /// A flat feather at height z: its base at (x, y), its vane a rectangle from x to x + length
  /// along +x, `width` across, three triangles fanned from the base.
  void add(uint64_t id, float x, float y, float z, float length, float width, float scale) {
    const int b = int(positions.size());
    for (const Vector3f &p : {Vector3f(x, y, z), Vector3f(x, y + width / 2, z), Vector3f(x + length, y + width / 2, z),
                              Vector3f(x + length, y - width / 2, z), Vector3f(x, y - width / 2, z)})
      positions.push_back(scale * p);
    for (int k = 1; k <= 3; ++k) {
      triangles.emplace_back(b, b + k, b + k + 1);
      ids.push_back(id);
    }
    first_vertex.push_back(int64_t(positions.size()));
  }
};

/// A slab of skin: the box [-5, 5] x [-5, 5] x [z0, z1], faces outward.
void add_slab(Mesh &mesh, float z0, float z1, float scale) {
  const int b = int(mesh.positions.size());
  for (int k = 0; k < 8; ++k)
    mesh.positions.push_back(scale * Vector3f(k & 1 ? 5.0f : -5.0f, k & 2 ? 5.0f : -5.0f, k & 4 ? z1 : z0));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto &q : quads) {
    mesh.triangles.emplace_back(b + q[0], b + q[1], b + q[2]);
    mesh.triangles.emplace_back(b + q[0], b + q[2], b + q[3]);
  }
}

Mesh slab_skin(float scale, bool second_slab = false) {
  Mesh mesh;
  add_slab(mesh, -1.0f, 0.0f, scale);
  if (second_slab) add_slab(mesh, 0.15f, 0.17f, scale);
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

check::VaneOverlaps overlaps_of(const Vanes &v, const Mesh &skin) {
  const MeshQuery query(skin);
  return check::vane_overlaps(v.positions, v.triangles, v.ids, skin, query);
}

}  // namespace

TEST_CASE("a planted layer-order violation is found, and none when the order agrees", "[check]") {
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO("scale " << scale);
    // Feather 7 lies low, feather 3 over its tip; feather 9 far away, over nothing.
    Vanes v;
    v.add(7, 0.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    v.add(3, 0.5f, 0.0f, 0.2f, 1.0f, 0.6f, scale);
    v.add(9, -3.0f, 2.0f, 0.1f, 1.0f, 0.3f, scale);
    const Mesh skin = slab_skin(scale);
    const check::VaneOverlaps overlaps = overlaps_of(v, skin);
    REQUIRE(overlaps.over.size() == 1);
    CHECK(overlaps.over[0] == check::Overlap{7, 3});
    CHECK(overlaps.samples == 12);  // four vertices per feather; the bases are in their root discs

    const check::LayerOrderReport agrees = check::layer_order_violations(overlaps, {{7, 0}, {3, 1}, {9, 2}});
    CHECK(agrees.overlapping_pairs == 1);
    CHECK(agrees.violations == 0);
    const check::LayerOrderReport planted = check::layer_order_violations(overlaps, {{7, 2}, {3, 1}, {9, 0}});
    CHECK(planted.violations == 1);
    REQUIRE(planted.examples.size() == 1);
    CHECK(planted.examples[0] == std::pair<uint64_t, uint64_t>(3, 7));  // (lower, higher) by the order
    const check::LayerOrderReport unranked = check::layer_order_violations(overlaps, {{7, 0}});
    CHECK(unranked.unranked_pairs == 1);
    CHECK(unranked.violations == 0);
  }
}

TEST_CASE("a feather beyond a layer of skin is not over the feathers below it", "[check]") {
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO("scale " << scale);
    Vanes v;
    // Feather 1 is nearest the lower slab's top, so its way out is +z, into the second slab.
    v.add(1, 0.0f, 0.0f, 0.05f, 1.0f, 0.3f, scale);
    v.add(2, 0.0f, 0.0f, 0.3f, 1.0f, 0.6f, scale);
    CHECK(overlaps_of(v, slab_skin(scale)).over.size() == 1);
    CHECK(overlaps_of(v, slab_skin(scale, true)).over.empty());  // a second slab between them
  }
}

TEST_CASE("two feathers that swap places between frames are an order flip", "[check]") {
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO("scale " << scale);
    const Mesh skin = slab_skin(scale);
    Vanes before, same, after;
    before.add(4, 0.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    before.add(5, 0.5f, 0.0f, 0.2f, 1.0f, 0.6f, scale);
    same.add(4, 0.0f, 0.0f, 0.12f, 1.0f, 0.3f, scale);
    same.add(5, 0.5f, 0.0f, 0.25f, 1.0f, 0.6f, scale);
    after.add(4, 0.0f, 0.0f, 0.3f, 1.0f, 0.8f, scale);
    after.add(5, 0.5f, 0.0f, 0.2f, 1.0f, 0.6f, scale);
    const check::VaneOverlaps a = overlaps_of(before, skin), b = overlaps_of(same, skin), c = overlaps_of(after, skin);
    const check::OrderFlips kept = check::order_flips(a, b);
    CHECK(kept.pairs_in_both == 1);
    CHECK(kept.flips == 0);
    const check::OrderFlips flipped = check::order_flips(a, c);
    CHECK(flipped.pairs_in_both == 1);
    CHECK(flipped.flips == 1);
    REQUIRE(flipped.examples.size() == 1);
    CHECK(flipped.examples[0] == std::pair<uint64_t, uint64_t>(5, 4));  // (outer before, outer now)
  }
}

TEST_CASE("a planted pop is measured in rachis widths; a rigid move of skin and feathers is none", "[check]") {
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO("scale " << scale);
    Vanes v;
    v.add(11, 0.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    v.add(12, 2.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    SurfaceFrame at_11, at_12;
    at_11.origin = scale * Vector3f(0.0f, 0.0f, 0.0f);
    at_12.origin = scale * Vector3f(2.0f, 0.0f, 0.0f);
    const std::vector<SurfaceFrame> frames{at_11, at_12};
    const std::vector<float> widths{0.02f * scale, 0.02f * scale};
    const std::vector<uint64_t> ids{11, 12};

    // Feather 12's tip jumps 0.3 rachis widths sideways.
    std::vector<Vector3f> popped = v.positions;
    popped[7] += Vector3f(0.0f, 0.006f * scale, 0.0f);
    const check::Popping pop = check::popping(v.positions, popped, v.first_vertex, frames, frames, widths, ids);
    CHECK(pop.largest == Approx(0.3).epsilon(1e-3));
    CHECK(pop.worst_feather == 12);
    CHECK(pop.largest_distance == Approx(0.006 * scale).epsilon(1e-3));

    // The skin frames and the feathers turned 40 degrees and moved together: nothing pops.
    const Eigen::Matrix3f turn = Eigen::AngleAxisf(0.7f, Vector3f(0.3f, -0.5f, 0.8f).normalized()).toRotationMatrix();
    const Vector3f shift = scale * Vector3f(3.0f, -1.0f, 2.0f);
    std::vector<Vector3f> moved;
    for (const Vector3f &p : v.positions) moved.push_back(turn * p + shift);
    std::vector<SurfaceFrame> moved_frames = frames;
    for (SurfaceFrame &f : moved_frames) {
      f.origin = turn * f.origin + shift;
      f.basis = turn * f.basis;
    }
    const check::Popping still = check::popping(v.positions, moved, v.first_vertex, frames, moved_frames, widths, ids);
    CHECK(still.largest < 1e-3);
    // The same move with the skin left behind is a large jump.
    CHECK(check::popping(v.positions, moved, v.first_vertex, frames, frames, widths, ids).largest > 10.0);
  }
}

TEST_CASE("shape drift ignores rigid motion and measures a shrunk feather in % of its length", "[check]") {
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO("scale " << scale);
    Vanes v;
    v.add(21, 0.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    v.add(22, 2.0f, 0.0f, 0.1f, 1.0f, 0.3f, scale);
    const std::vector<float> lengths{1.0f * scale, 1.0f * scale};
    const std::vector<uint64_t> ids{21, 22};
    const Eigen::Matrix3f turn = Eigen::AngleAxisf(1.1f, Vector3f(0.2f, 0.9f, -0.4f).normalized()).toRotationMatrix();
    std::vector<Vector3f> moved;
    for (const Vector3f &p : v.positions) moved.push_back(turn * p + scale * Vector3f(-4.0f, 1.0f, 0.5f));
    const check::ShapeDrift rigid = check::shape_drift(moved, v.positions, v.first_vertex, lengths, ids);
    CHECK(rigid.largest < 1e-5);
    CHECK(rigid.mean < 1e-5);

    // Feather 22 shrunk to 0.8 about its base: no rotation fits a scaled copy better than none, so
    // its drift is 0.2 x its farthest vertex from the centroid (0.4, 0): (1, 0.15), 0.6185 away.
    std::vector<Vector3f> shrunk = moved;
    const Vector3f base = shrunk[5];
    for (int k = 6; k < 10; ++k) shrunk[size_t(k)] = base + 0.8f * (shrunk[size_t(k)] - base);
    const check::ShapeDrift drift = check::shape_drift(shrunk, v.positions, v.first_vertex, lengths, ids);
    CHECK(drift.worst_feather == 22);
    CHECK(drift.largest == Approx(0.2 * std::sqrt(0.6 * 0.6 + 0.15 * 0.15)).epsilon(1e-3));
    CHECK(drift.mean == Approx(drift.largest / 2).epsilon(1e-3));
  }
}
