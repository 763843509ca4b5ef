// The feather checker's order and motion measures on hand-made vanes whose answer is known: a
// planted order violation is found (and not when the order agrees), the skin stops the way out, a
// swapped pair is an order flip, a planted pop is measured in rachis widths, a rigid move of skin and
// feathers together is no pop, and shape drift ignores rigid motion but measures a shrunk feather. Every case
// again at scales 1e-3 and 1e3 (no absolute unit). On random flat coats over a flat skin, the
// overlaps equal an exact 2-D answer, and violations and flips counted by brute force agree.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <unordered_map>

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

namespace {

/// A flat plane of skin at z = 0, facing +z (its vertex normals exactly +z).
Mesh plane_skin(float scale) {
  Mesh mesh;
  for (const Vector3f &p : {Vector3f(-1000, -1000, 0), Vector3f(1000, -1000, 0), Vector3f(1000, 1000, 0),
                            Vector3f(-1000, 1000, 0)})
    mesh.positions.push_back(scale * p);
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangle_groups = {0, 0};
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

struct Flat {
  float x, y, z, length, width;
};

}  // namespace

TEST_CASE("which feather is over which agrees with an exact 2-D answer on random flat coats", "[check]") {
  // Flat rectangular vanes parallel to a flat skin: feather i is over feather j exactly when a vertex
  // of j outside its root disc lies inside i's rectangle seen from above, i higher than j, within
  // i's extent. Pairs decided within 1e-4 of an edge or a threshold are left out of the comparison.
  std::mt19937 random(2024);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int64_t compared = 0, overlapping = 0, ranked = 0;
  for (int seed = 0; seed < 60; ++seed) {
    const float scale = seed % 3 == 0 ? 1.0f : seed % 3 == 1 ? 1e-3f : 1e3f;
    std::vector<Flat> flats;
    for (int f = 0; f < 24; ++f)
      flats.push_back({4.0f * unit(random), 4.0f * unit(random), 0.05f + 0.5f * unit(random), 0.4f + 1.2f * unit(random),
                       0.1f + 0.6f * unit(random)});
    Vanes v;
    for (size_t f = 0; f < flats.size(); ++f)
      v.add(uint64_t(100 + f), flats[f].x, flats[f].y, flats[f].z, flats[f].length, flats[f].width, scale);
    const Mesh skin = plane_skin(scale);
    const check::VaneOverlaps found = overlaps_of(v, skin);

    std::set<std::pair<uint64_t, uint64_t>> expected, uncertain;
    for (size_t j = 0; j < flats.size(); ++j) {
      const Flat &b = flats[j];
      for (int k = 1; k <= 4; ++k) {
        const Vector3f p = v.positions[size_t(v.first_vertex[j] + k)] / scale;
        // No ray from a vertex in its feather's root disc (5% of its extent from its base).
        const double from_base = std::hypot(p.x() - b.x, p.y() - b.y), disc = 0.05 * std::hypot(b.length, b.width / 2);
        if (std::abs(from_base - disc) < 1e-4) {
          for (size_t i = 0; i < flats.size(); ++i) uncertain.insert({100 + j, 100 + i});
          continue;
        }
        if (from_base < disc) continue;
        for (size_t i = 0; i < flats.size(); ++i) {
          if (i == j) continue;
          const Flat &a = flats[i];
          const double inside = std::min({p.x() - a.x, a.x + a.length - p.x(), p.y() - (a.y - a.width / 2),
                                          a.y + a.width / 2 - p.y()});
          const double above = a.z - b.z;
          const double extent = std::hypot(a.length, a.width / 2);
          const std::pair<uint64_t, uint64_t> pair(100 + j, 100 + i);
          if (std::abs(inside) < 1e-4 || std::abs(above) < 1e-4 || std::abs(above - extent) < 1e-4) {
            uncertain.insert(pair);
            continue;
          }
          if (inside > 0 && above > 0 && above <= extent) expected.insert(pair);
        }
      }
    }
    std::set<std::pair<uint64_t, uint64_t>> got;
    for (const check::Overlap &o : found.over) got.insert({o.inner, o.outer});
    for (const auto &pair : uncertain) {
      expected.erase(pair);
      got.erase(pair);
    }
    INFO("seed " << seed << ", scale " << scale);
    CHECK(got == expected);
    compared += int64_t(flats.size() * flats.size());
    overlapping += int64_t(expected.size());

    // Violations against a random order, and flips against the coat with every height reversed,
    // counted by brute force over the expected pairs.
    std::unordered_map<uint64_t, int64_t> rank;
    std::vector<int64_t> places(flats.size());
    std::iota(places.begin(), places.end(), 0);
    std::shuffle(places.begin(), places.end(), random);
    for (size_t f = 0; f < flats.size(); ++f) rank[100 + f] = places[f];
    if (uncertain.empty()) {
      ++ranked;
      std::set<std::pair<uint64_t, uint64_t>> wrong;
      for (const auto &[inner, outer] : expected)
        if (rank[outer] < rank[inner]) wrong.insert({std::min(inner, outer), std::max(inner, outer)});
      CHECK(check::layer_order_violations(found, rank).violations == int64_t(wrong.size()));
      Vanes reversed;
      for (size_t f = 0; f < flats.size(); ++f)
        reversed.add(uint64_t(100 + f), flats[f].x, flats[f].y, 0.6f - flats[f].z, flats[f].length, flats[f].width,
                     scale);
      std::set<std::pair<uint64_t, uint64_t>> one_way;
      for (const auto &[inner, outer] : expected)
        if (!expected.count({outer, inner})) one_way.insert({std::min(inner, outer), std::max(inner, outer)});
      // Reversed heights turn every pair seen one way only to the other way, where the reversed coat
      // sees it (the vertices that saw it may no longer): at most that many flips, and no pair seen
      // both ways before can flip.
      const check::OrderFlips flips = check::order_flips(found, overlaps_of(reversed, skin));
      CHECK(flips.flips <= int64_t(one_way.size()));
      for (const auto &[before, now] : flips.examples) CHECK(one_way.count({std::min(before, now), std::max(before, now)}));
    }
  }
  CHECK(overlapping > 200);  // the coats do overlap
  CHECK(ranked > 40);        // and most have no pair near a threshold
  CHECK(compared == 60 * 24 * 24);
}
