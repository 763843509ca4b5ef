// The layer order a groom gives (issue 28, section 1): key feathers' `layer`, `layers.map`, and
// front and rear tracts order the bird's feathers whatever covers what at rest; coverage orders the
// feathers of equal keys; coverings the keys reverse are reported, cycles broken only within equal
// keys; the same keys everywhere give the order from coverage alone; unknown tracts are named.
#include <catch2/catch.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "check/vanes.h"
#include "feathers/coat.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume;
using namespace plume::feathers;

namespace {

const std::string kBird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";

/// The bird's groom read from grooms/bird/, with layering on.
struct Bird {
  GroomDesc groom = io::read_groom_file(kBird + "bird.groom.yaml");
  Mesh rest = io::read_obj_mesh(kBird + "bird.obj");
  Guides stems;
  Bird() {
    groom.feathers.layers = true;
    stems = bind_guides(MeshQuery(rest), io::read_strands(kBird + "stems.obj"), "stems.obj");
  }
  /// A coat of `count` feathers bound with the groom's feathers as `edit` leaves them.
  std::unique_ptr<Coat> bind(int64_t count, const std::function<void(FeatherDesc &)> &edit,
                             std::span<const float> layer_map = {}) const {
    FeatherDesc desc = groom.feathers;
    edit(desc);
    return std::make_unique<Coat>(rest, stems, desc, scatter_follicles(rest, desc.follicles, {}, count), layer_map);
  }
  /// The face group of feather i's follicle.
  std::string tract(const Coat &coat, size_t i) const {
    return rest.group_names[size_t(rest.triangle_groups[size_t(coat.follicles()[i].triangle)])];
  }
};

const auto kUnchanged = [](FeatherDesc &) {};

/// Checks that `order` puts every feather with a smaller `key` below every feather with a larger
/// one, and that every covering it broke or overrode is one the keys allow.
template <class Key>
void check_keys_kept(const LayerOrder &order, Key key) {
  const size_t n = order.rank.size();
  // Along the order from the bottom, the keys never fall.
  size_t falls = 0;
  for (size_t r = 1; r < n; ++r)
    if (key(size_t(order.bottom_up[r])) < key(size_t(order.bottom_up[r - 1]))) ++falls;
  CHECK(falls == 0);
  for (const auto &[covering, covered] : order.overridden) {
    CHECK(key(size_t(covering)) < key(size_t(covered)));
    CHECK(order.rank[size_t(covering)] < order.rank[size_t(covered)]);
  }
  // A cycle is broken only among feathers of equal keys.
  for (const auto &[covering, covered] : order.broken) CHECK_FALSE(key(size_t(covering)) < key(size_t(covered)));
}

}  // namespace

TEST_CASE("key feathers' layers order the bird's tracts, against what covers what at rest", "[feathers]") {
  const Bird bird;
  // Flight feathers above the coverts that cover their bases at rest, the down above everything.
  const auto edit = [](FeatherDesc &d) {
    for (KeyFeather &k : d.key_feathers) {
      k.layer_given = true;
      k.layer = k.template_name == "down" ? 9.0f : k.template_name == "flight" ? 5.0f : k.template_name == "covert" ? 4.0f : 1.0f;
    }
  };
  const std::unique_ptr<Coat> coat = bird.bind(700, edit);
  const std::unique_ptr<Coat> plain = bird.bind(700, kUnchanged);
  const LayerOrder &order = coat->layer_order();
  REQUIRE(order.bottom_up.size() == coat->size());
  FeatherDesc desc = bird.groom.feathers;
  edit(desc);
  const auto key = [&](size_t i) {
    const std::span<const float> w = coat->key_weights(i);
    return desc.key_feathers[size_t(std::max_element(w.begin(), w.end()) - w.begin())].layer;
  };
  check_keys_kept(order, key);
  // The keys reverse coverings the plain order keeps (down lies under the contour feathers at rest).
  CHECK(order.overridden.size() > 20);
  CHECK(plain->layer_order().overridden.empty());
  CHECK(order.coverings == plain->layer_order().coverings);
  // Within one key, coverage still orders: the contour feathers' relative order is the plain one
  // wherever no cycle was broken differently.
  std::vector<int32_t> contour_here, contour_plain;
  for (const int32_t f : order.bottom_up)
    if (key(size_t(f)) == 1.0f) contour_here.push_back(f);
  for (const int32_t f : plain->layer_order().bottom_up)
    if (key(size_t(f)) == 1.0f) contour_plain.push_back(f);
  REQUIRE(contour_here.size() == contour_plain.size());
  REQUIRE(contour_here.size() > 100);
  // Measured by consecutive pairs of the plain order (a feather's place shifts wherever a cycle
  // through other tracts was broken differently; the pairs keep their order).
  std::vector<int32_t> place(coat->size(), -1);
  for (size_t i = 0; i < contour_here.size(); ++i) place[size_t(contour_here[i])] = int32_t(i);
  size_t same = 0;
  for (size_t i = 1; i < contour_plain.size(); ++i)
    same += place[size_t(contour_plain[i - 1])] < place[size_t(contour_plain[i])] ? 1 : 0;
  INFO(same << " of " << contour_plain.size() - 1 << " consecutive contour pairs in the same order");
  CHECK(same * 4 > 3 * (contour_plain.size() - 1));
}

TEST_CASE("the same layer on every key feather gives the order from coverage alone", "[feathers]") {
  const Bird bird;
  const std::unique_ptr<Coat> given = bird.bind(600, [](FeatherDesc &d) {
    for (KeyFeather &k : d.key_feathers) {
      k.layer_given = true;
      k.layer = 3.0f;
    }
  });
  const std::unique_ptr<Coat> plain = bird.bind(600, kUnchanged);
  CHECK(given->layer_order().bottom_up == plain->layer_order().bottom_up);
  CHECK(given->layer_order().broken == plain->layer_order().broken);
  CHECK(given->layer_order().overridden.empty());
}

TEST_CASE("front and rear tracts lie above and below every other feather", "[feathers]") {
  const Bird bird;
  const std::unique_ptr<Coat> coat = bird.bind(700, [](FeatherDesc &d) {
    d.layer_front = {"belly"};
    d.layer_rear = {"left_wing", "right_wing"};
  });
  const auto tier = [&](size_t i) {
    const std::string t = bird.tract(*coat, i);
    return t == "belly" ? 1 : (t == "left_wing" || t == "right_wing") ? -1 : 0;
  };
  size_t front = 0, rear = 0;
  for (size_t i = 0; i < coat->size(); ++i) {
    if (tier(i) > 0) ++front;
    if (tier(i) < 0) ++rear;
  }
  REQUIRE(front > 20);
  REQUIRE(rear > 20);
  check_keys_kept(coat->layer_order(), tier);
  CHECK_FALSE(coat->layer_order().overridden.empty());
}

TEST_CASE("a layer map orders feathers by its value at their follicles", "[feathers]") {
  const Bird bird;
  // Higher on the body lies above: the map is each vertex's height, from 0 to 1.
  float lo = INFINITY, hi = -INFINITY;
  for (const Eigen::Vector3f &p : bird.rest.positions) {
    lo = std::min(lo, p.y());
    hi = std::max(hi, p.y());
  }
  std::vector<float> map;
  for (const Eigen::Vector3f &p : bird.rest.positions) map.push_back((p.y() - lo) / (hi - lo));
  const std::unique_ptr<Coat> coat = bird.bind(700, kUnchanged, map);
  const auto height = [&](size_t i) { return surface_position(bird.rest, coat->follicles()[i]).y(); };
  // The map is linear in height over each triangle, so its value at a follicle is the follicle's
  // height, rescaled: feathers go up the body from the bottom of the order, within rounding.
  const LayerOrder &order = coat->layer_order();
  size_t falls = 0;
  for (size_t r = 1; r < order.bottom_up.size(); ++r)
    if (height(size_t(order.bottom_up[r])) < height(size_t(order.bottom_up[r - 1])) - 1e-4f * (hi - lo)) ++falls;
  CHECK(falls == 0);
  CHECK(order.broken.empty());  // no two follicles at one height: nothing left for coverage to order
  CHECK_FALSE(order.overridden.empty());
}

TEST_CASE("an unknown front or rear tract is named with the emitter's groups", "[feathers]") {
  const Bird bird;
  for (const bool front : {true, false}) {
    try {
      bird.bind(50, [&](FeatherDesc &d) { (front ? d.layer_front : d.layer_rear) = {"back", "wingz"}; });
      FAIL("an unknown tract was accepted");
    } catch (const InputError &e) {
      const std::string message = e.what();
      INFO(message);
      CHECK(message.find(front ? "feathers.layers.front" : "feathers.layers.rear") != std::string::npos);
      CHECK(message.find("\"wingz\"") != std::string::npos);
      CHECK(message.find("left_wing") != std::string::npos);
    }
  }
}

TEST_CASE("the layering pass keeps vanes apart in the groom's own order, reversed tracts included", "[feathers]") {
  const Bird bird;
  // Flight feathers in front of the coverts that cover their bases at rest, the belly behind all.
  const std::unique_ptr<Coat> coat = bird.bind(500, [](FeatherDesc &d) {
    d.layer_front = {"left_flight", "right_flight"};
    d.layer_rear = {"belly"};
  });
  REQUIRE_FALSE(coat->layer_order().overridden.empty());
  const MeshQuery query(bird.rest);
  CoatFrame frame;
  coat->grow(bird.rest, query, bird.stems.strands, frame);
  const check::VaneCheckReport report =
      check::check_vanes(frame.vanes.positions, frame.vanes.triangles, frame.vanes.triangle_feathers);
  CHECK(report.feather_pairs == 0);
  CHECK(frame.layering.lifted > 0);
}

namespace {

/// Moller and Trumbore in double, as the order computes it: how far along the unit `direction` from
/// `origin` the ray crosses triangle (a, b, c), or -1.
double ray_crossing(const Eigen::Vector3d &origin, const Eigen::Vector3d &direction, const Eigen::Vector3d &a,
                    const Eigen::Vector3d &b, const Eigen::Vector3d &c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, h = direction.cross(e2);
  const double det = e1.dot(h);
  if (!(std::abs(det) > 1e-300)) return -1.0;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(h) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return e2.dot(q) / det;
}

/// The order layer_order_from_coverage documents (no keys), by brute force: every ray against every
/// triangle of every feather whose sphere it may reach, no boxes, no tree.
LayerOrder brute_force_order(const CoatFrame &rest, const FeatherRanges &ranges, const MeshQuery &skin) {
  using Vec = Eigen::Vector3d;
  const size_t n = ranges.size();
  const auto position = [&](int64_t x) { return Vec(rest.vanes.positions[size_t(x)].cast<double>()); };
  std::vector<Vec> roots(n);
  std::vector<double> extents(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    roots[i] = rest.root_frames[i].origin.cast<double>();
    if (ranges.first_triangle[i] == ranges.first_triangle[i + 1]) continue;
    for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
      extents[i] = std::max(extents[i], (position(x) - roots[i]).norm());
  }
  // Whether the ray meets feather i's vanes farther than `from` and within i's extent.
  const auto meets = [&](const Vec &origin, const Vec &direction, size_t i, double from) {
    for (int64_t t = ranges.first_triangle[i]; t < ranges.first_triangle[i + 1]; ++t) {
      const auto &tri = rest.vanes.triangles[size_t(t)];
      const double along = ray_crossing(origin, direction, position(tri[0]), position(tri[1]), position(tri[2]));
      if (along > from && along <= extents[i]) return true;
    }
    return false;
  };
  std::vector<std::vector<int32_t>> covers(n);
  std::vector<std::vector<std::pair<int32_t, double>>> over(n);
  for (size_t j = 0; j < n; ++j) {
    for (size_t i = 0; i < n; ++i)
      if (i != j && (roots[i] - roots[j]).norm() <= extents[i] + extents[j] &&
          meets(roots[j], rest.root_frames[j].normal().cast<double>(), i, 0.0))
        covers[i].push_back(int32_t(j));
    const int64_t v0 = ranges.first_vertex[j], v1 = ranges.first_vertex[j + 1];
    if (v0 == v1 || ranges.first_triangle[j] == ranges.first_triangle[j + 1]) continue;
    const Vec base = position(rest.vanes.triangles[size_t(ranges.first_triangle[j])][0]);
    double from_base = 0.0;
    for (int64_t x = v0; x < v1; ++x) from_base = std::max(from_base, (position(x) - base).norm());
    std::vector<double> nearest(n, 2.0);
    for (int64_t x = v0; x < v1; ++x) {
      const Vec p = position(x);
      if ((p - base).norm() <= 0.05 * from_base) continue;  // the checker's root disc
      const double from_root = (p - roots[j]).norm() / std::max(extents[j], 1e-300);
      const Vec out = surface_normal(skin.mesh(), skin.closest(rest.vanes.positions[size_t(x)])).cast<double>();
      for (size_t i = 0; i < n; ++i)
        if (i != j && (roots[i] - roots[j]).norm() <= 2.0 * extents[i] + 2.0 * extents[j] && from_root < nearest[i] &&
            meets(p, out, i, 1e-4 * extents[j]))
          nearest[i] = from_root;
    }
    for (size_t i = 0; i < n; ++i)
      if (nearest[i] <= 1.0) over[j].emplace_back(int32_t(i), nearest[i]);
  }
  const auto nearer_from = [&](size_t j, int32_t i) {
    for (const auto &[k, nearer] : over[j])
      if (k == i) return nearer;
    return 2.0;
  };
  const auto has = [](const std::vector<int32_t> &list, int32_t k) {
    return std::find(list.begin(), list.end(), k) != list.end();
  };
  std::vector<std::vector<int32_t>> lies_over(n);
  for (size_t j = 0; j < n; ++j)
    for (const auto &[i, nearer] : over[j]) {
      if (has(covers[j], i) || has(covers[size_t(i)], int32_t(j))) continue;
      const double against = nearer_from(size_t(i), int32_t(j));
      if (nearer < against || (nearer == against && i > int32_t(j))) lies_over[size_t(i)].push_back(int32_t(j));
    }
  // Kahn's order: the next feather covers the fewest remaining roots, then lies above the fewest
  // remaining feathers, then has the smallest index.
  LayerOrder order;
  order.rank.assign(n, -1);
  std::vector<bool> placed(n, false);
  for (size_t step = 0; step < n; ++step) {
    std::tuple<int32_t, int32_t, int32_t> best{INT32_MAX, INT32_MAX, INT32_MAX};
    for (size_t i = 0; i < n; ++i) {
      if (placed[i]) continue;
      int32_t roots_left = 0, left = 0;
      for (const int32_t k : covers[i]) roots_left += placed[size_t(k)] ? 0 : 1;
      for (const int32_t k : lies_over[i]) left += placed[size_t(k)] ? 0 : 1;
      best = std::min(best, {roots_left, roots_left + left, int32_t(i)});
    }
    const int32_t i = std::get<2>(best);
    for (const int32_t k : covers[size_t(i)])
      if (!placed[size_t(k)]) order.broken.emplace_back(i, k);
    for (const int32_t k : lies_over[size_t(i)])
      if (!placed[size_t(k)]) order.loose.emplace_back(i, k);
    placed[size_t(i)] = true;
    order.rank[size_t(i)] = int32_t(order.bottom_up.size());
    order.bottom_up.push_back(i);
  }
  std::sort(order.loose.begin(), order.loose.end());
  return order;
}

}  // namespace

TEST_CASE("the order at rest is the one every ray against every triangle gives", "[feathers]") {
  const Bird bird;
  FeatherDesc desc = bird.groom.feathers;
  desc.layers = false;
  desc.follicles.groups = {"back"};
  const Coat coat(bird.rest, bird.stems, desc, scatter_follicles(bird.rest, desc.follicles, {}, 70));
  const MeshQuery query(bird.rest);
  CoatFrame rest;
  coat.grow(bird.rest, query, bird.stems.strands, rest);
  const LayerOrder order = layer_order_from_coverage(rest, coat.ranges(), {}, &query);
  const LayerOrder reference = brute_force_order(rest, coat.ranges(), query);
  REQUIRE(order.bottom_up.size() == coat.size());
  CHECK(order.bottom_up == reference.bottom_up);
  CHECK(order.broken == reference.broken);
  CHECK(order.loose == reference.loose);
}
