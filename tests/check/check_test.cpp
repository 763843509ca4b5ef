// The strand checker (check/check.h): skin, crossings and their classes, zones, guide deviation,
// requested roots, the effects rule and the verdict.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>

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
  CHECK(count.transversal_pairs == 1);
  CHECK(count.touching_pairs == 0);
  CHECK(count.largest_angle_degrees == Approx(90.0).margin(1e-3));
  REQUIRE(count.transversal_examples.size() == 1);
  CHECK(count.transversal_examples[0] == std::make_pair(uint64_t(10), uint64_t(20)));
  CHECK(count.touching_examples.empty());
  // With a tolerance wider than the gap between the parallel strands they all meet: 10 and 30 side
  // by side (touching), 20 across both.
  const CrossingCount wide = count_crossings(strands, 0.6f, 8);
  CHECK(wide.pairs == 3);
  CHECK(wide.transversal_pairs == 2);
  CHECK(wide.touching_pairs == 1);
  CHECK(wide.touching_examples == std::vector<std::pair<uint64_t, uint64_t>>{{10, 30}});
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
  CheckReport report = check_strands(strands, query, options);
  CHECK(report.crossings.tolerance == 0.01f);
  CHECK(report.crossings.pairs == 0);
  CHECK(report.points_inside_skin == 0);
  CHECK(report.clean());
  CHECK(report.violations().empty());
  CHECK(report.crossings.segment_pairs_examined > 0);
  // By default the crossings are counted too, at 1e-3 of the median segment length (0.03 here).
  report = check_strands(strands, query, CheckOptions{});
  std::vector<float> lengths;
  for (size_t i = 0; i < strands.strand_count(); ++i)
    for (size_t j = 1; j < 16; ++j) lengths.push_back((strands.points(i)[j] - strands.points(i)[j - 1]).norm());
  std::sort(lengths.begin(), lengths.end());
  CHECK(report.median_segment_length == Approx(lengths[lengths.size() / 2]).epsilon(1e-6));
  CHECK(report.crossings.tolerance == Approx(1e-3 * report.median_segment_length).epsilon(1e-6));
  CHECK(report.crossings.pairs == 0);
  CHECK(report.clean());
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
  CHECK(count.transversal_pairs + count.touching_pairs == count.pairs);
  // Each kind keeps its 8 lowest pairs: together they hold the 8 lowest of all, (0, 1) .. (0, 8).
  std::vector<std::pair<uint64_t, uint64_t>> lowest = count.transversal_examples;
  lowest.insert(lowest.end(), count.touching_examples.begin(), count.touching_examples.end());
  std::sort(lowest.begin(), lowest.end());
  REQUIRE(lowest.size() >= 8);
  for (uint64_t b = 1; b <= 8; ++b) CHECK(lowest[b - 1] == std::make_pair(uint64_t(0), b));
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
  CheckInputs inputs;
  inputs.partings = &field;
  inputs.roots = &roots;
  inputs.binding = &binding;
  const CheckReport report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.zones_checked);
  CHECK(report.cross_zone_influences == 1);
  CHECK_FALSE(report.clean());
  REQUIRE(report.violations().size() == 1);
  CHECK(report.violations()[0] == "1 influence across hard partings");
}


TEST_CASE("strands side by side within the tolerance touch; strands meeting at an angle above 10 degrees cross", "[check]") {
  // Pairs of straight strands 1 long (10 segments): tolerance 0.001 (1e-3 of the segment length).
  const auto pair_at = [](float angle_degrees, float gap) {
    StrandSet strands;
    strands.append(line_points({0, 0, 0}, {1, 0, 0}, 11), 1);
    // The second turns about (0.5, gap, 0) by `angle_degrees` in the plane z = 0.
    const float a = angle_degrees * float(M_PI) / 180.0f;
    const Eigen::Vector3f d(0.5f * std::cos(a), 0.5f * std::sin(a), 0.0f), centre(0.5f, gap, 0.0f);
    strands.append(line_points(centre - d, centre + d, 11), 2);
    return strands;
  };
  const auto count = [](const StrandSet &strands, float degrees = kTransversalDegrees) {
    return count_crossings(strands, 0.001f, 8, degrees);
  };
  // Parallel, 0.0005 apart: touching. 0.002 apart: nothing.
  CrossingCount c = count(pair_at(0.0f, 0.0005f));
  CHECK(c.pairs == 1);
  CHECK(c.touching_pairs == 1);
  CHECK(c.transversal_pairs == 0);
  CHECK(c.largest_angle_degrees < 0.01);
  CHECK(count(pair_at(0.0f, 0.002f)).pairs == 0);
  // Antiparallel is parallel too: a strand curling back along another touches it.
  StrandSet back;
  back.append(line_points({0, 0, 0}, {1, 0, 0}, 11), 1);
  back.append(line_points({1, 0.0005f, 0}, {0, 0.0005f, 0}, 11), 2);
  CHECK(count(back).touching_pairs == 1);
  // Crossing through each other at 5 degrees: touching; at 15, 30 and 90 degrees: transversal.
  c = count(pair_at(5.0f, 0.0f));
  CHECK(c.touching_pairs == 1);
  CHECK(c.transversal_pairs == 0);
  CHECK(c.largest_angle_degrees == Approx(5.0).margin(0.01));
  for (const float angle : {15.0f, 30.0f, 90.0f}) {
    INFO(angle);
    c = count(pair_at(angle, 0.0f));
    CHECK(c.transversal_pairs == 1);
    CHECK(c.touching_pairs == 0);
    CHECK(c.largest_angle_degrees == Approx(angle).margin(0.01));
  }
  // The threshold is an option: at 4 degrees a 5-degree crossing is transversal, at 20 a 15-degree one touches.
  CHECK(count(pair_at(5.0f, 0.0f), 4.0f).transversal_pairs == 1);
  CHECK(count(pair_at(15.0f, 0.0f), 20.0f).touching_pairs == 1);
  // Passing over each other at 90 degrees, 0.0005 apart in z (within the tolerance) or 0.002 (not).
  StrandSet over;
  over.append(line_points({0, 0, 0}, {1, 0, 0}, 11), 1);
  over.append(line_points({0.55f, -0.5f, 0.0005f}, {0.55f, 0.5f, 0.0005f}, 11), 2);
  CHECK(count(over).transversal_pairs == 1);
  for (Eigen::Vector3f &p : over.points_for_write(1)) p.z() = 0.002f;
  CHECK(count(over).pairs == 0);
  // One pair with a near-parallel stretch and a transversal meeting is transversal, counted once.
  StrandSet both;
  both.append(line_points({0, 0, 0}, {1, 0, 0}, 11), 1);
  std::vector<Eigen::Vector3f> hook = line_points({0, 0.0005f, 0}, {0.5f, 0.0005f, 0}, 6);
  for (const Eigen::Vector3f &p : line_points({0.6f, 0.1f, 0}, {0.6f, -0.5f, 0}, 7)) hook.push_back(p);
  both.append(hook, 2);
  c = count(both);
  CHECK(c.pairs == 1);
  CHECK(c.transversal_pairs == 1);
}

TEST_CASE("the default tolerance scales with the strands: a scaled copy gives the same counts", "[check]") {
  const Mesh grid = make_grid(10);
  // Wavy strands, some pairs crossing (every fifth strand leans across its neighbours), some touching.
  StrandSet strands = wavy_field(10, 0.015f);
  for (size_t s = 0; s < strands.strand_count(); s += 5)
    for (Eigen::Vector3f &p : strands.points_for_write(s)) p.x() += 2.0f * p.z() * 0.1f;
  std::vector<Eigen::Vector3f> copy(strands.points(3).begin(), strands.points(3).end());
  for (Eigen::Vector3f &p : copy) p.y() += 1e-5f;  // 1e-5 beside strand 3: touching at 1e-3 x 0.03
  strands.append(copy, 1000);
  const auto counts_at = [&](float scale) {
    StrandSet scaled = strands;
    for (Eigen::Vector3f &p : scaled.positions) p *= scale;
    Mesh mesh = grid;
    for (Eigen::Vector3f &p : mesh.positions) p *= scale;
    mesh.compute_normals();
    const MeshQuery query(mesh);
    const CheckReport report = check_strands(scaled, query, CheckOptions{});
    CHECK(report.crossings.tolerance == Approx(1e-3 * report.median_segment_length).epsilon(1e-6));
    CHECK(report.median_segment_length == Approx(scale * median_segment_length(strands)).epsilon(1e-5));
    return std::make_tuple(report.crossings.pairs, report.crossings.transversal_pairs, report.crossings.touching_pairs,
                           report.points_inside_skin);
  };
  const auto base = counts_at(1.0f);
  CHECK(std::get<1>(base) > 0);
  CHECK(std::get<2>(base) == 1);
  CHECK(counts_at(0.01f) == base);
  CHECK(counts_at(100.0f) == base);
}

TEST_CASE("no tolerance can be derived from strands without length: an InputError, not a silent pass", "[check]") {
  const Mesh grid = make_grid(4);
  const MeshQuery query(grid);
  StrandSet strands;
  strands.append(Points{{0, 0, 0.1f}, {0, 0, 0.1f}}, 1);
  CHECK_THROWS_AS(check_strands(strands, query, CheckOptions{}), InputError);
  CheckOptions options;
  options.crossing_tolerance = 0.01f;
  CHECK(check_strands(strands, query, options).crossings.pairs == 0);
}

TEST_CASE("the checker measures how far strands at guide roots stray from their guide", "[check]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}, {0.5f, 0.0f, 0}}, 0.5f, 8);
  StrandSet strands = guides.strands;
  strands.append(line_points({0.1f, 0.1f, 0}, {0.1f, 0.1f, 0.5f}, 8), 99);  // not at a guide root
  CheckInputs inputs;
  inputs.guides = &guides;
  CheckReport report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.guides_checked);
  CHECK(report.guide_deviation.strands_at_guide_roots == 2);
  CHECK(report.guide_deviation.largest == Approx(0.0).margin(1e-6));
  CHECK(report.guide_deviation.over_limit == 0);
  CHECK(report.clean());
  // Bend strand 1's tip by 0.05 sideways: its deviation is that, 10% of the guide's length.
  strands.points_for_write(1).back() += Eigen::Vector3f(0.05f, 0.0f, 0.0f);
  report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.guide_deviation.worst_strand == strands.ids[1]);
  CHECK(report.guide_deviation.largest == Approx(0.05).epsilon(1e-4));
  CHECK(report.guide_deviation.largest_relative == Approx(0.1).epsilon(1e-4));
  CHECK(report.guide_deviation.over_limit == 1);
  CHECK(report.guide_deviation.over_limit_examples == std::vector<uint64_t>{strands.ids[1]});
  REQUIRE(report.violations().size() == 1);
  CHECK(report.violations()[0] == "1 strand at guide roots deviating from their guide by more than 0.1% of its length");
  // 0.04% of the length is within the default 0.1%, over a limit of 0.03%.
  strands.points_for_write(1).back() -= Eigen::Vector3f(0.05f - 0.0002f, 0.0f, 0.0f);
  report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.guide_deviation.largest_relative == Approx(4e-4).epsilon(1e-2));
  CHECK(report.guide_deviation.over_limit == 0);
  CheckOptions tight;
  tight.guide_deviation_limit = 3e-4;
  CHECK(check_strands(strands, query, tight, inputs).guide_deviation.over_limit == 1);
}

TEST_CASE("guide deviation: chords of a resampled strand are not charged, a short strand is, coils never swap", "[check]") {
  // A helix of 3 turns, radius 0.1, pitch 0.05 (coils 0.05 apart), 97 points; the guide.
  const auto helix = [](int count, float turns, float phase) {
    Points points;
    for (int i = 0; i < count; ++i) {
      const float t = float(i) / float(count - 1), a = 2.0f * float(M_PI) * turns * t + phase;
      points.emplace_back(0.1f * std::cos(a) - 0.1f * std::cos(phase), 0.1f * std::sin(a) - 0.1f * std::sin(phase),
                          0.05f * turns * t);
    }
    return points;
  };
  const Points guide = helix(97, 3.0f, 0.0f);
  double length = 0.0;
  // The guide itself, and the guide resampled to 25 of its points (every 4th: chords 1.5% of the
  // length, sagging 0.0026 off the curve): both reproduce it.
  CHECK(guide_deviation(guide, guide.front(), guide, length) == 0.0);
  const double guide_length = length;
  Points every_fourth;
  for (size_t i = 0; i < guide.size(); i += 4) every_fourth.push_back(guide[i]);
  CHECK(guide_deviation(every_fourth, guide.front(), guide, length) < 1e-6 * guide_length);
  // Stopping at 97% of the guide's length: deviates by about the 3% it lacks (the tips).
  Points short_strand(guide.begin(), guide.end() - 3);
  const double lacking = (guide.back() - short_strand.back()).norm();
  CHECK(guide_deviation(short_strand, guide.front(), guide, length) >= lacking * (1.0 - 1e-6));
  CHECK(guide_deviation(short_strand, guide.front(), guide, length) / guide_length > 0.005);
  // A strand one coil further up (0.05 away, on the next coil) is not matched to that coil: its
  // points are compared with the guide near the same arc length.
  Points lifted = guide;
  for (Eigen::Vector3f &p : lifted) p.z() += 0.05f;
  lifted.front() = guide.front();
  CHECK(guide_deviation(lifted, guide.front(), guide, length) >= 0.049);
  // Another phase of the same helix, starting at the same root: the curl is another; far off.
  CHECK(guide_deviation(helix(97, 3.0f, 1.0f), guide.front(), guide, length) > 0.05);
}

TEST_CASE("guide deviation: a guide floating above the skin is joined to its root there", "[check]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  // A guide whose first point is 0.05 above the skin, 0.5 long above that.
  StrandSet guide_strands;
  guide_strands.append(line_points({0.2f, 0.2f, 0.05f}, {0.2f, 0.2f, 0.55f}, 8), 0);
  const Guides guides = bind_guides(query, guide_strands, "guide");
  CheckInputs inputs;
  inputs.guides = &guides;
  // A strand from the skin up through the guide: reproduces the guide joined to the skin.
  StrandSet strands;
  strands.append(line_points({0.2f, 0.2f, 0.0f}, {0.2f, 0.2f, 0.55f}, 12), 1);
  // A strand starting at the guide's first point, along it: reproduces the guide as it is.
  strands.append(line_points({0.2f, 0.2f, 0.05f}, {0.2f, 0.2f, 0.55f}, 12), 2);
  CheckReport report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.guide_deviation.strands_at_guide_roots == 2);
  CHECK(report.guide_deviation.largest < 1e-5);
  // The guide shifted sideways on the skin (its own root's shape translated) is 0.05 off at the top.
  StrandSet shifted;
  shifted.append(line_points({0.2f, 0.2f, 0.0f}, {0.2f, 0.2f, 0.5f}, 12), 3);
  report = check_strands(shifted, query, CheckOptions{}, inputs);
  CHECK(report.guide_deviation.strands_at_guide_roots == 1);
  CHECK(report.guide_deviation.largest == Approx(0.05).epsilon(1e-3));
}

TEST_CASE("every requested root has a strand: lifted roots are found, missing roots counted", "[check]") {
  const Mesh sphere = make_closed_sphere(1.0f, 24, 48);
  const MeshQuery query(sphere);
  // Roots spread over the sphere; the strands stand on them along the surface normal, lifted by up
  // to 0.1 (as Plume lifts roots under floating guides), and every third root gets no strand.
  std::vector<SurfacePoint> roots;
  StrandSet strands;
  for (int i = 0; i < 300; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / 300.0f, a = 2.39996f * float(i);
    const Eigen::Vector3f direction(std::sqrt(1.0f - z * z) * std::cos(a), std::sqrt(1.0f - z * z) * std::sin(a), z);
    roots.push_back(query.closest(direction));
    if (i % 3 == 2) continue;
    const Eigen::Vector3f c = surface_position(sphere, roots.back()), n = surface_normal(sphere, roots.back());
    const float lift = 0.1f * float(i % 7) / 6.0f;
    strands.append(line_points(c + lift * n, c + (lift + 0.3f) * n, 5), uint64_t(i));
  }
  CheckInputs inputs;
  inputs.requested_roots = &roots;
  CheckReport report = check_strands(strands, query, CheckOptions{}, inputs);
  CHECK(report.roots_checked);
  CHECK(report.requested_roots.requested == 300);
  CHECK(report.requested_roots.missing == 100);
  CHECK(report.requested_roots.missing_examples == std::vector<size_t>{2, 5, 8, 11, 14, 17, 20, 23});
  CHECK(report.violations() == std::vector<std::string>{"100 requested roots without a strand"});
  // A strand beside its root (0.01 sideways, far beyond the root tolerance) is not its strand.
  const std::vector<int64_t> found = strands_at_roots(strands, nullptr, sphere, roots, report.root_tolerance);
  CHECK(found[0] == 0);
  StrandSet beside = strands;
  for (Eigen::Vector3f &p : beside.points_for_write(0)) p += 0.01f * surface_frame(sphere, roots[0]).basis.col(0);
  CHECK(strands_at_roots(beside, nullptr, sphere, roots, report.root_tolerance)[0] == -1);
  // With the roots the strands grew from, a strand moved sideways off its root's normal line (as
  // linear growth starts a strand at its guides' blended first points) is still its root's.
  Roots grown;
  for (size_t i = 0; i < roots.size(); ++i)
    if (i % 3 != 2) {
      grown.points.push_back(roots[i]);
      grown.ids.push_back(i);
    }
  CHECK(strands_at_roots(beside, &grown, sphere, roots, report.root_tolerance)[0] == 0);
  inputs.roots = &grown;
  inputs.roots_grown = true;
  CheckReport by_roots = check_strands(beside, query, CheckOptions{}, inputs);
  CHECK(by_roots.requested_roots.missing == 100);
  CHECK(by_roots.requested_roots.missing_examples == report.requested_roots.missing_examples);
  // Every root with a strand: none missing.
  std::vector<SurfacePoint> kept;
  for (size_t i = 0; i < roots.size(); ++i)
    if (i % 3 != 2) kept.push_back(roots[i]);
  inputs.requested_roots = &kept;
  CHECK(check_strands(strands, query, CheckOptions{}, inputs).requested_roots.missing == 0);
}

TEST_CASE("with the strands before effects, crossings and guides are judged on them; after effects, a figure", "[check]") {
  const Mesh grid = make_grid(10);
  const MeshQuery query(grid);
  // Before effects: two parallel strands 0.1 apart. After (a clump twisted through): they cross.
  StrandSet before, after;
  before.append(line_points({0, 0, 0}, {0, 0, 1}, 11), 1);
  before.append(line_points({0.1f, 0, 0}, {0.1f, 0, 1}, 11), 2);
  after.append(line_points({0, 0, 0}, {0.15f, 0, 1}, 11), 1);
  after.append(line_points({0.1f, 0, 0}, {-0.05f, 0, 1}, 11), 2);
  CheckReport report = check_strands(after, query, CheckOptions{});
  CHECK(report.crossings.pairs == 1);
  CHECK_FALSE(report.clean());
  CheckInputs inputs;
  inputs.interpolated = &before;
  report = check_strands(after, query, CheckOptions{}, inputs);
  CHECK(report.crossings_before_effects);
  CHECK(report.crossings.pairs == 0);
  CHECK(report.crossings_after_effects.pairs == 1);
  CHECK(report.crossings_after_effects.transversal_pairs == 1);
  CHECK(report.crossings_after_effects.pairs_new == 1);  // the effects made it
  CHECK(report.crossings_after_effects.transversal_pairs_new == 1);
  CHECK(report.clean());
  // Crossings before the effects are still violations.
  StrandSet crossing = before;
  crossing.points_for_write(1).back() = Eigen::Vector3f(-0.1f, 0, 1);
  crossing.points_for_write(1)[9] = Eigen::Vector3f(-0.08f, 0, 0.9f);
  inputs.interpolated = &crossing;
  report = check_strands(after, query, CheckOptions{}, inputs);
  CHECK(report.crossings.transversal_pairs == 1);
  CHECK(report.crossings_after_effects.pairs == 1);
  CHECK(report.crossings_after_effects.pairs_new == 0);  // it crossed before the effects already
  CHECK(report.violations() == std::vector<std::string>{"1 transversal crossing pair (before effects)"});
  // Strands before effects that are not the same roots are refused.
  StrandSet other = before;
  other.points_for_write(0)[0].x() += 0.05f;
  inputs.interpolated = &other;
  CHECK_THROWS_AS(check_strands(after, query, CheckOptions{}, inputs), InputError);
}

TEST_CASE("the verdict: touching pairs are violations only when asked", "[check]") {
  const Mesh grid = make_grid(10);
  const MeshQuery query(grid);
  StrandSet strands;
  strands.append(line_points({0, 0, 0}, {0, 0, 1}, 11), 1);
  strands.append(line_points({0.00005f, 0, 0.05f}, {0.00005f, 0, 1}, 11), 2);  // 5e-5 beside strand 1
  CheckReport report = check_strands(strands, query, CheckOptions{});
  CHECK(report.crossings.touching_pairs == 1);
  CHECK(report.clean());
  CheckOptions options;
  options.touching_is_violation = true;
  report = check_strands(strands, query, options);
  CHECK(report.violations() == std::vector<std::string>{"1 touching pair"});
  // Points inside the skin are always violations.
  strands.points_for_write(0)[5].z() = -0.1f;
  report = check_strands(strands, query, CheckOptions{});
  CHECK(report.points_inside_skin == 1);
  CHECK(report.violations() == std::vector<std::string>{"1 point inside the skin"});
}
