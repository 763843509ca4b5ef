// Feathers kept apart: on the bird of grooms/bird/ the checker (check/vanes.h, CGAL's exact
// triangle-triangle predicates, independent of the layering's own distance code) finds vanes
// through each other without the layering pass and none with it: at rest, with the wing open and
// the neck bent, in a coat turned into itself, with a thin offset, in a millimetre copy; the order is
// the coverage order with its broken cycles named; same bytes for 1 and 2 threads.
#include <catch2/catch.hpp>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>

#include "check/feather_layers.h"
#include "check/vanes.h"
#include "feather_fixtures.h"
#include "feathers/coat.h"
#include "groom/mesh_query.h"

using namespace plume;
using namespace plume::feathers;

namespace {

/// The bird with `follicles` feathers (a subset of its 5,000), its groom's feathers changed by an edit.
using LayeredBird = test::BirdCoat;

check::VaneCheckReport check_frame(const CoatFrame &frame) {
  return check::check_vanes(frame.vanes.positions, frame.vanes.triangles, frame.vanes.triangle_feathers);
}

const auto kAsShipped = [](FeatherDesc &d) { d.layers = true; };
const auto kNoLayers = [](FeatherDesc &d) { d.layers = false; };

/// The 600-feather proxy of the bird without the layering pass (`layers` false) and as shipped,
/// built once for the cases that ask for it.
const LayeredBird &proxy(bool layers) {
  static const LayeredBird without(600, kNoLayers), with(600, kAsShipped);
  return layers ? with : without;
}

/// The proxy's coat grown stateless at `frame_number` (0: at rest), grown once for every case that
/// asks for that frame.
const CoatFrame &proxy_frame(bool layers, int frame_number) {
  static std::map<std::pair<bool, int>, CoatFrame> frames;
  const auto [at, fresh] = frames.try_emplace({layers, frame_number});
  if (fresh) {
    const LayeredBird &bird = proxy(layers);
    at->second = bird.grow(frame_number == 0 ? bird.rest : bird.pose(frame_number));
  }
  return at->second;
}

/// The checker's overlaps (who lies over whom) on the proxy grown at rest without the pass,
/// measured once.
const check::VaneOverlaps &rest_overlaps_without() {
  static const check::VaneOverlaps overlaps = [] {
    const CoatFrame &rest = proxy_frame(false, 0);
    const Mesh &skin = proxy(false).rest;
    return check::vane_overlaps(rest.vanes.positions, rest.vanes.triangles, rest.vanes.triangle_feathers, skin,
                                MeshQuery(skin));
  }();
  return overlaps;
}

}  // namespace

TEST_CASE("the checker finds vanes through each other without layering and none with it, on the bird's frames",
          "[feathers]") {
  const LayeredBird &without = proxy(false);
  // At rest; the wing half open and the neck bending; the wing open and the neck bent 90 degrees.
  for (const int frame_number : {1, 14, 24, 36}) {
    const Mesh posed = without.pose(frame_number);
    const CoatFrame &before = proxy_frame(false, frame_number), &after = proxy_frame(true, frame_number);
    const check::VaneCheckReport a = check_frame(before), b = check_frame(after);
    INFO("frame " << frame_number << ": " << a.feather_pairs << " feather pairs meet without layering, "
                  << b.feather_pairs << " with (" << after.layering.lifted << " lifted, " << after.layering.unresolved
                  << " shrunk, " << after.layering.waves << " waves)");
    CHECK(a.feather_pairs > 50);
    CHECK(b.feather_pairs == 0);
    CHECK(b.intersecting_triangle_pairs == 0);
    CHECK(test::vane_points_below_skin(posed, after, 1e-5f * 40.0f) == 0);
  }
}

TEST_CASE("a higher feather lies under a lower one only where the layering pass reports it could not lift it out",
          "[feathers]") {
  // The checker's rule (check/feather_layers.h: CGAL rays along the skin normal from every vane vertex,
  // independent of the pass's own rays) against the frozen order. The pass lifts every feather out
  // from under the lower ones it overlaps where a turn up to the skin normal does; where none does
  // (a lower feather lifted steeply beside it, or one over it near its root), it turns the feather
  // aside (a yaw about the skin normal) or bends it along its shaft where that takes it out, else takes
  // the turn, or the bend, under the fewest and names the feather. Every violation must be one of those named; and they are few: fewer
  // than a sixth of the violations of the coat grown without the pass (measured on the 600-feather
  // proxy: 41 of 359 at rest, 20 of 393 at frame 24).
  const LayeredBird &with = proxy(true);
  std::unordered_map<uint64_t, int64_t> rank;
  std::unordered_map<uint64_t, int32_t> index;
  for (size_t i = 0; i < with.coat->size(); ++i) {
    rank.emplace(with.coat->ids()[i], with.coat->layer_order().rank[i]);
    index.emplace(with.coat->ids()[i], int32_t(i));
  }
  for (const int frame_number : {0, 24}) {
    const Mesh posed = frame_number == 0 ? with.rest : with.pose(frame_number);
    const MeshQuery query(posed);
    const CoatFrame &before = proxy_frame(false, frame_number), &after = proxy_frame(true, frame_number);
    auto violations = [&](const CoatFrame &frame) {
      return check::layer_order_violations(check::vane_overlaps(frame.vanes.positions, frame.vanes.triangles,
                                                                frame.vanes.triangle_feathers, posed, query),
                                           rank, SIZE_MAX);
    };
    const check::LayerOrderReport a = frame_number == 0 ? check::layer_order_violations(rest_overlaps_without(), rank,
                                                                                        SIZE_MAX)
                                                        : violations(before),
                                  b = violations(after);
    const std::vector<int32_t> &named = after.layering.unordered;
    INFO("frame " << frame_number << ": " << a.violations << " layer-order violations without the pass, "
                  << b.violations << " with; " << named.size() << " feathers named (" << after.layering.left_under
                  << " left under, " << after.layering.unresolved << " shrunk), " << after.layering.turned_aside
                  << " turned aside");
    CHECK(std::is_sorted(named.begin(), named.end()));
    CHECK(int64_t(named.size()) <= after.layering.left_under + after.layering.unresolved);
    CHECK(check_frame(after).feather_pairs == 0);
    CHECK(a.violations > 300);
    CHECK(6 * b.violations < a.violations);
    CHECK(after.layering.turned_aside > 0);
    CHECK(after.layering.bent > 0);
    CHECK(named.size() * 5 < with.coat->size());
    // A bent feather moves whole: its rachis and barbs stay on its vanes. Per bent feather, the
    // farthest curve point from the nearest vane vertex is, within a tenth of the feather's extent, as
    // far as in the coat grown without the pass (the same feather before the pass, the skin pass
    // alike); curves left behind would lie up to a fifth of its extent off.
    const FeatherRanges ranges = with.coat->ranges();
    int64_t bent = 0;
    for (size_t i = 0; i < with.coat->size(); ++i) {
      if (after.layer_state.bends[i] == 0.0f) continue;
      ++bent;
      const auto off_vanes = [&](const CoatFrame &frame) {
        double farthest = 0.0;
        for (int64_t p = ranges.first_point[i]; p < ranges.first_point[i + 1]; ++p) {
          double nearest = HUGE_VAL;
          for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
            nearest = std::min(nearest, double((frame.curves.curves.positions[size_t(p)] -
                                                frame.vanes.positions[size_t(x)]).norm()));
          farthest = std::max(farthest, nearest);
        }
        return farthest;
      };
      double extent = 0.0;
      for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
        extent = std::max(extent, double((before.vanes.positions[size_t(x)] - before.root_frames[i].origin).norm()));
      INFO("bent feather " << i << ", bend " << after.layer_state.bends[i]);
      CHECK(off_vanes(after) <= off_vanes(before) + 0.1 * extent);
    }
    CHECK(bent == after.layering.bent);
    for (const auto &[lower, higher] : b.examples) {
      INFO("feather " << higher << " under the lower " << lower);
      CHECK(std::binary_search(named.begin(), named.end(), index.at(higher)));
    }
  }
}

TEST_CASE("a coat turned into itself is pulled apart: thin offsets, a dense patch, steep turns", "[feathers]") {
  // Feathers turned down into the skin and sideways into each other by up to 40 degrees, on the back
  // and breast only (a dense patch), with an offset ten times thinner than the default.
  const auto rotated = [](FeatherDesc &d) {
    d.layers = true;
    d.variation.direction = 40.0f;
    d.variation.lift = 20.0f;
    d.follicles.groups = {"back", "breast"};
    d.layer_offset = 2e-4f;
  };
  const auto rotated_unlayered = [&](FeatherDesc &d) {
    rotated(d);
    d.layers = false;
  };
  const LayeredBird without(700, rotated_unlayered), with(700, rotated);
  const CoatFrame before = without.grow(without.rest), after = with.grow(with.rest);
  const check::VaneCheckReport a = check_frame(before), b = check_frame(after);
  const size_t below_before = test::vane_points_below_skin(without.rest, before, 1e-5f * 40.0f);
  const size_t below_after = test::vane_points_below_skin(with.rest, after, 1e-5f * 40.0f);
  INFO(a.feather_pairs << " pairs before, " << b.feather_pairs << " after; vane vertices below the skin "
                       << below_before << " before, " << below_after << " after");
  CHECK(a.feather_pairs > 200);
  CHECK(b.feather_pairs == 0);
  // The skin pass leaves a few vertices of feathers turned 20 degrees into the skin below it (it
  // samples the vanes, rows and barb midpoints and tips); layering adds none.
  CHECK(below_after <= below_before);
}

TEST_CASE("layering keeps feathers apart in a millimetre copy of the bird", "[feathers]") {
  const LayeredBird mm(500, kAsShipped, 10.0f);
  const CoatFrame frame = mm.grow(mm.pose(24));
  const check::VaneCheckReport report = check_frame(frame);
  CHECK(report.feather_pairs == 0);
  CHECK(report.thickness > 0.0);
}

TEST_CASE("the layer order keeps every covering above the covered feather, but for the broken cycles it names",
          "[feathers]") {
  const LayeredBird bird(800, kAsShipped);
  const LayerOrder &order = bird.coat->layer_order();
  REQUIRE(order.bottom_up.size() == bird.coat->size());
  CHECK(order.coverings > 100);
  std::vector<bool> seen(bird.coat->size(), false);
  for (size_t r = 0; r < order.bottom_up.size(); ++r) {
    const int32_t f = order.bottom_up[r];
    CHECK(order.rank[size_t(f)] == int32_t(r));
    CHECK_FALSE(seen[size_t(f)]);
    seen[size_t(f)] = true;
  }
  // Every broken covering has its covering feather below the covered one; the order is frozen: the
  // same coat bound again gives it again.
  for (const auto &[covering, covered] : order.broken) CHECK(order.rank[size_t(covering)] < order.rank[size_t(covered)]);
  const LayeredBird again(800, kAsShipped);
  CHECK(again.coat->layer_order().bottom_up == order.bottom_up);
}

TEST_CASE("the layer order agrees with the rest pose away from the roots, as the checker sees it", "[feathers]") {
  // The checker's rays (check/feather_layers.h, CGAL, from every vane vertex outside the root disc)
  // on the coat grown at rest without the pass: where one feather lies over another and never under
  // it, the order puts it above, unless the order names that covering as broken in a cycle. (An
  // order from the roots' coverings alone left a third of the overlapping pairs against it.)
  const LayeredBird &with = proxy(true);
  const LayerOrder &order = with.coat->layer_order();
  std::unordered_map<uint64_t, int32_t> index;
  for (size_t i = 0; i < with.coat->size(); ++i) index.emplace(with.coat->ids()[i], int32_t(i));
  const check::VaneOverlaps &overlaps = rest_overlaps_without();
  std::set<std::pair<uint64_t, uint64_t>> seen;  // (inner, outer)
  for (const check::Overlap &o : overlaps.over) seen.emplace(o.inner, o.outer);
  int64_t one_way = 0, against = 0;
  for (const auto &[inner, outer] : seen) {
    if (seen.count({outer, inner})) continue;
    ++one_way;
    const int32_t i = index.at(outer), j = index.at(inner);
    if (order.rank[size_t(i)] > order.rank[size_t(j)]) continue;
    const std::pair<int32_t, int32_t> pair(i, j);
    const bool broken = std::find(order.broken.begin(), order.broken.end(), pair) != order.broken.end() ||
                        std::binary_search(order.loose.begin(), order.loose.end(), pair);
    against += broken ? 0 : 1;
  }
  INFO(one_way << " pairs overlapping one way at rest, " << against << " against the order; " << order.broken.size()
               << " roots' coverings and " << order.loose.size() << " other overlaps broken in cycles");
  // A few may stand against it where the order's rays and the checker's part: a root's covering the
  // other way (the checker casts no ray from the root disc), or a way out stopped by the skin (the
  // checker stops there; the order does not). Measured: 4 of 1,476.
  CHECK(one_way > 500);
  CHECK(against * 100 < one_way);
  CHECK((order.broken.size() + order.loose.size()) * 10 < size_t(one_way));
}

TEST_CASE("a layered frame is the same to the bit for 1 and 2 threads", "[feathers]") {
  const LayeredBird bird(500, kAsShipped);
  const Mesh posed = bird.pose(30);
  omp_set_num_threads(1);
  const CoatFrame one = bird.grow(posed);
  omp_set_num_threads(2);
  const CoatFrame two = bird.grow(posed);
  CHECK(one.vanes.positions == two.vanes.positions);
  CHECK(one.curves.curves.positions == two.curves.curves.positions);
  CHECK(one.lifts == two.lifts);
  CHECK(one.scales == two.scales);
}
