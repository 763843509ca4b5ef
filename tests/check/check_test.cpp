// The strand checker (check/check.h): skin, crossings, zones, guide deviation.
#include <catch2/catch.hpp>

#include <cmath>

#include "check/check.h"
#include "parting/parting_fixtures.h"

using namespace plume;
using namespace plume::interp;
using namespace plume::partings;
using namespace plume::check;
using plume::test::make_closed_sphere;
using plume::test::make_grid;
using plume::test::make_standing_guides;

namespace {

using Points = std::vector<Eigen::Vector3f>;

Points line_points(const Eigen::Vector3f &a, const Eigen::Vector3f &b, int count) {
  Points points;
  for (int i = 0; i < count; ++i) points.push_back(a + (b - a) * float(i) / float(count - 1));
  return points;
}

/// side x side wavy strands standing on the plane z = 0, `spacing` apart, 16 points each; they
/// all wave the same way so they never come closer than the spacing.
StrandSet wavy_field(int side, float spacing) {
  StrandSet strands;
  Points points(16);
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const Eigen::Vector3f root(float(i) * spacing, float(j) * spacing, 0.0f);
      for (int p = 0; p < 16; ++p) {
        const float z = 0.03f * float(p);
        points[size_t(p)] = root + Eigen::Vector3f(0.02f * std::sin(10.0f * z), 0.0f, z);
      }
      strands.append(points, uint64_t(j * side + i));
    }
  return strands;
}

}  // namespace

TEST_CASE("the checker finds a known crossing, and only it", "[check]") {
  StrandSet strands;
  strands.append(line_points({0, 0, 0}, {1, 0, 1}, 11), 10);
  strands.append(line_points({1, 0, 0}, {0, 0, 1}, 11), 20);    // crosses strand 10 at (0.5, 0, 0.5)
  strands.append(line_points({0, 0.5f, 0}, {1, 0.5f, 1}, 11), 30);  // parallel to 10, 0.5 away
  const CrossingCount count = count_crossings(strands, 0.01f, 8);
  CHECK(count.pairs == 1);
  REQUIRE(count.examples.size() == 1);
  CHECK(count.examples[0] == std::make_pair(uint64_t(10), uint64_t(20)));
  // With a tolerance wider than the gap between the parallel strands they all touch.
  CHECK(count_crossings(strands, 0.6f, 8).pairs == 3);
}

TEST_CASE("strands from roots closer than the tolerance only cross beyond their first segments", "[check]") {
  StrandSet strands;
  strands.append(line_points({0, 0, 0}, {-1, 0, 1}, 11), 1);
  strands.append(line_points({0.005f, 0, 0}, {1, 0, 1}, 11), 2);  // a V from nearly the same root
  CHECK(count_crossings(strands, 0.01f, 8).pairs == 0);
  strands.append(line_points({0.0f, 0.004f, 0}, {-1, 0.004f, 1}, 11), 3);  // runs along strand 1
  CHECK(count_crossings(strands, 0.01f, 8).pairs == 1);
}

TEST_CASE("the checker finds known points inside the skin", "[check]") {
  const Mesh sphere = make_closed_sphere(1.0f, 24, 48);
  const MeshQuery query(sphere);
  StrandSet strands;
  strands.append(line_points({0, 1, 0}, {0, 2, 0}, 6), 5);                 // outward: clean
  strands.append(Points{{1, 0, 0}, {0.8f, 0, 0}, {0.6f, 0, 0}}, 6);        // two points inside
  strands.append(line_points({0, 0, 1}, {0, 0, 3}, 32), 7);                // long and outside
  strands.append(Points{{0, -1, 0}, {0, -1.5f, 0}, {0, -0.5f, 0}}, 8);     // comes back in at its tip
  std::vector<uint64_t> examples;
  CHECK(count_points_inside(strands, query, 0.0f, 8, examples) == 3);
  CHECK(examples == std::vector<uint64_t>{6, 8});
  // A margin counts points that are outside but too close; roots stay exempt.
  StrandSet close;
  close.append(Points{{0, 1, 0}, {0, 1.005f, 0}, {0, 1.5f, 0}}, 1);
  CHECK(count_points_inside(close, query, 0.0f, 8, examples) == 0);
  CHECK(count_points_inside(close, query, 0.01f, 8, examples) == 1);
}

TEST_CASE("the checker reports nothing on clean synthetic strands", "[check]") {
  const Mesh grid = make_grid(10);
  const MeshQuery query(grid);
  // 0.015 apart: neighbours share grid cells (so pairs are examined) but stay beyond the tolerance.
  StrandSet strands = wavy_field(20, 0.015f);
  for (Eigen::Vector3f &p : strands.positions) p -= Eigen::Vector3f(0.15f, 0.15f, 0.0f);
  CheckOptions options;
  options.crossing_tolerance = 0.01f;
  const CheckReport report = check_strands(strands, query, options);
  CHECK(report.crossings_checked);
  CHECK(report.crossing_pairs == 0);
  CHECK(report.points_inside_skin == 0);
  CHECK(report.clean());
  CHECK(report.segment_pairs_examined > 0);
}

TEST_CASE("the crossing count is not all pairs: examined pairs grow linearly with the strand count", "[check]") {
  // Strands closer than a grid cell (0.02 here), so every strand has neighbours to examine.
  const CrossingCount small = count_crossings(wavy_field(20, 0.015f), 0.01f, 8);
  const CrossingCount large = count_crossings(wavy_field(40, 0.015f), 0.01f, 8);
  CHECK(small.segment_pairs_examined > 0);
  CHECK(small.pairs == 0);
  CHECK(large.pairs == 0);
  // Four times the strands at the same density: about four times the work, where all pairs
  // would be sixteen times.
  const double ratio = double(large.segment_pairs_examined) / double(small.segment_pairs_examined);
  CHECK(ratio > 3.0);
  CHECK(ratio < 5.0);
  const double segments = 1600.0 * 15.0;
  CHECK(double(large.segment_pairs_examined) < 0.01 * segments * segments / 2.0);
}

TEST_CASE("a tolerance that crosses every strand pair is counted exactly, without storing the pairs", "[check]") {
  // 144 strands 0.015 apart: at tolerance 1 every pair crosses (beyond the first segments).
  const StrandSet strands = wavy_field(12, 0.015f);
  const CrossingCount count = count_crossings(strands, 1.0f, 8);
  CHECK(count.pairs == 144 * 143 / 2);
  REQUIRE(count.examples.size() == 8);
  for (uint64_t b = 1; b <= 8; ++b) CHECK(count.examples[b - 1] == std::make_pair(uint64_t(0), b));
  // The work stays within the budget the grid measured before comparing.
  const double segments = 144.0 * 15.0;
  CHECK(count.segment_pairs_examined <= count.piece_pairs_binned);
  CHECK(double(count.piece_pairs_binned) <= kCrossingPiecePairsPerSegment * segments);
}

TEST_CASE("a tolerance beyond the crossing budget is refused before any comparison", "[check]") {
  // 400 strands x 15 segments in a 0.3 x 0.3 x 0.45 box: at tolerance 10 they all share one cell,
  // 6000 pieces, 3000 piece pairs per segment, over the budget.
  const StrandSet strands = wavy_field(20, 0.015f);
  REQUIRE(kCrossingPiecePairsPerSegment < 6000.0 * 5999.0 / 2.0 / 6000.0);
  CHECK_THROWS_AS(count_crossings(strands, 10.0f, 8), InputError);
  CHECK_THROWS_WITH(count_crossings(strands, 10.0f, 8), Catch::Contains("crossing tolerance 10"));
  // check_strands passes the refusal on.
  const Mesh plane = make_grid(4);
  const MeshQuery query(plane);
  CheckOptions options;
  options.crossing_tolerance = 10.0f;
  CHECK_THROWS_AS(check_strands(strands, query, options), InputError);
  // The shipped kind of tolerance, far below the strands' spacing, is well within it.
  const CrossingCount count = count_crossings(strands, 0.005f, 8);
  CHECK(count.pairs == 0);
  CHECK(double(count.piece_pairs_binned) < 0.05 * kCrossingPiecePairsPerSegment * 6000.0);
}

TEST_CASE("strands too far from the origin for the tolerance are refused before the grid is allocated", "[check]") {
  // The wavy field scaled up 20 times (strands 0.3 apart, segments 0.6 long: cells of 0.2), then
  // moved 1e6 away: float coordinates there are 0.06 apart, and the rounding slack of a piece's
  // box (1e-6 of its coordinates, about 1.7) spans some 18 cells per axis.
  auto field_at = [](float offset) {
    StrandSet strands = wavy_field(4, 0.015f);
    for (Eigen::Vector3f &p : strands.positions) p = 20.0f * p + Eigen::Vector3f::Constant(offset);
    return strands;
  };
  CHECK_THROWS_AS(count_crossings(field_at(1e6f), 0.001f, 8), InputError);
  CHECK_THROWS_WITH(count_crossings(field_at(1e6f), 0.001f, 8), Catch::Contains("from the origin"));
  // Near the origin, or a moderate distance from it (rounding well below a cell), the same strands
  // are counted: only a grid that the rounding dominates is refused.
  CHECK(count_crossings(field_at(0.0f), 0.001f, 8).pairs == 0);
  CHECK(count_crossings(field_at(1e3f), 0.001f, 8).pairs == 0);
}

TEST_CASE("the checker counts influence across hard zones from a binding", "[check]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}, {0.5f, 0.0f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::face_groups;
  const PartingField field(mesh, guides, settings);
  Roots roots;
  roots.points = {query.closest({-0.3f, 0.2f, 0}), query.closest({0.3f, 0.2f, 0})};
  roots.ids = {100, 200};
  Binding binding;
  binding.k = 2;
  binding.guide_ids = {0, 1, 1, 0};        // root 100 uses guide 1 (right), root 200 uses guide 0 (left)
  binding.weights = {0.7f, 0.3f, 1.0f, 0.0f};  // ... but root 200's slot on guide 0 has no weight
  binding.lengths = {0.5f, 0.5f};
  std::vector<uint64_t> examples;
  CHECK(count_cross_zone_influences(field, roots, binding, 8, examples) == 1);
  CHECK(examples == std::vector<uint64_t>{100});
  StrandSet strands;
  strands.append(line_points({-0.3f, 0.2f, 0}, {-0.3f, 0.2f, 0.5f}, 4), 100);
  strands.append(line_points({0.3f, 0.2f, 0}, {0.3f, 0.2f, 0.5f}, 4), 200);
  const CheckReport report = check_strands(strands, query, CheckOptions{}, nullptr, &field, &roots, &binding);
  CHECK(report.zones_checked);
  CHECK(report.cross_zone_influences == 1);
  CHECK_FALSE(report.clean());
}

TEST_CASE("the checker measures how far strands at guide roots stray from their guide", "[check]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}, {0.5f, 0.0f, 0}}, 0.5f, 8);
  StrandSet strands = guides.strands;
  strands.append(line_points({0.1f, 0.1f, 0}, {0.1f, 0.1f, 0.5f}, 8), 99);  // not at a guide root
  CheckReport report = check_strands(strands, query, CheckOptions{}, &guides);
  CHECK(report.guides_checked);
  CHECK(report.strands_at_guide_roots == 2);
  CHECK(report.max_guide_deviation == Approx(0.0).margin(1e-6));
  // Bend strand 1's tip by 0.05 sideways: its deviation is that, 10% of the guide's length.
  strands.points_for_write(1).back() += Eigen::Vector3f(0.05f, 0.0f, 0.0f);
  report = check_strands(strands, query, CheckOptions{}, &guides);
  CHECK(report.worst_guide_strand == strands.ids[1]);
  CHECK(report.max_guide_deviation > 0.045);
  CHECK(report.max_guide_deviation < 0.06);
  CHECK(report.max_guide_deviation_relative == Approx(report.max_guide_deviation / 0.5).epsilon(1e-4));
}
