// Hard zones and partial partings (partings/parting_field.h), and their effect on bind().
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "check/check.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"
#include "parting/parting_fixtures.h"

using namespace plume;
using namespace plume::interp;
using namespace plume::partings;
using plume::check::count_cross_zone_influences;
using plume::test::make_grid;
using plume::test::make_standing_guides;
using plume::test::straight_line;

namespace {

SurfacePoint at(const MeshQuery &query, float x, float y) { return query.closest(Eigen::Vector3f(x, y, 0.0f)); }

std::string message_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const InputError &e) {
    return e.what();
  }
  return "(no InputError)";
}

size_t cross_zone_slots(const PartingField &partings, const Roots &roots, const Binding &binding) {
  std::vector<uint64_t> examples;
  return count_cross_zone_influences(partings, roots, binding, 4, examples);
}

}  // namespace

TEST_CASE("a partial parting's factor is continuous along the line and has no effect past its end", "[parting]") {
  const Mesh mesh = make_grid(40);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.21f, 0.12f, 0.0f}});
  PartingSettings settings;
  settings.lines.push_back(straight_line(-0.6f, 0.2f, 2.0f));
  const PartingField field(mesh, guides, settings);
  REQUIRE_FALSE(field.empty());
  REQUIRE(field.partial_line_count() == 1);

  // Paths parallel to the line on the side away from the guide, from before its start to past its
  // end. Continuity: the largest step between samples shrinks with the sampling step (a jump would
  // not), and past the end the factor is exactly 1.
  const auto largest_step = [&](float y, int samples, float &r_lowest) {
    float previous = -1.0f, largest = 0.0f;
    r_lowest = 1.0f;
    for (int i = 0; i <= samples; ++i) {
      const float x = -0.95f + 1.9f * float(i) / float(samples);
      const float f = field.weight_factor(at(query, x, y), 0);
      INFO("y " << y << " x " << x << " factor " << f);
      REQUIRE(f > 0.0f);
      REQUIRE(f <= 1.0f);
      if (x >= 0.85f) REQUIRE(f == Approx(1.0f).margin(1e-5));
      if (previous >= 0.0f) largest = std::max(largest, std::abs(f - previous));
      previous = f;
      r_lowest = std::min(r_lowest, f);
    }
    return largest;
  };
  for (const float y : {-0.1f, -0.01f}) {
    float lowest = 1.0f;
    const float coarse = largest_step(y, 200, lowest);
    const float fine = largest_step(y, 1600, lowest);
    INFO("y " << y << ": largest step " << coarse << " at 200 samples, " << fine << " at 1600");
    CHECK(fine < 0.3f * coarse);
    CHECK(fine < 0.03f);
    CHECK(lowest < 0.2f);  // the line does part: straight across it the weight drops
  }
}

TEST_CASE("a partial parting multiplies the weight by (D / D1)^gamma with surface distances", "[parting]") {
  const Mesh mesh = make_grid(40);
  const MeshQuery query(mesh);
  const Eigen::Vector3f h(-0.21f, 0.12f, 0.0f);
  const Guides guides = make_standing_guides(query, {h});
  PartingSettings settings;
  settings.lines.push_back(straight_line(-0.6f, 0.2f, 2.0f));
  const PartingField field(mesh, guides, settings);

  const Eigen::Vector3f c(-0.2f, -0.1f, 0.0f);
  const SurfacePoint root = query.closest(c);
  const float d = field.geodesic_distance(root, 0), d1 = field.detour_distance(root, 0, 0);
  // On the plane: D is the straight segment, D1 goes round the line's end at (0.2, 0).
  const Eigen::Vector3f tip(0.2f, 0.0f, 0.0f);
  CHECK(d == Approx((c - h).norm()).epsilon(0.08));
  CHECK(d1 == Approx((c - tip).norm() + (tip - h).norm()).epsilon(0.08));
  CHECK(field.weight_factor(root, 0) == Approx(std::pow(d / d1, 2.0f)).epsilon(1e-5));
  CHECK(field.weight_factor(root, 0) < 0.1f);

  // Roots far from the line skip the cut field; the factor still is the formula everywhere.
  for (int j = 0; j <= 20; ++j)
    for (int i = 0; i <= 20; ++i) {
      const SurfacePoint p = at(query, -0.97f + 0.097f * float(i), -0.97f + 0.097f * float(j));
      const float expected = std::pow(std::min(1.0f, field.geodesic_distance(p, 0) / field.detour_distance(p, 0, 0)), 2.0f);
      REQUIRE(field.weight_factor(p, 0) == Approx(expected).margin(1e-6));
    }
}

TEST_CASE("a root on the guide's side of a partial parting keeps the full weight", "[parting]") {
  const Mesh mesh = make_grid(40);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.21f, 0.12f, 0.0f}, {0.4f, -0.5f, 0.0f}});
  PartingSettings settings;
  settings.lines.push_back(straight_line(-0.6f, 0.2f, 3.0f));
  const PartingField field(mesh, guides, settings);
  for (const float x : {-0.93f, -0.6f, -0.21f, 0.0f, 0.19f, 0.6f})
    for (const float y : {0.02f, 0.3f, 0.9f}) {
      INFO("x " << x << " y " << y);
      CHECK(field.weight_factor(at(query, x, y), 0) == Approx(1.0f).margin(1e-5));
      CHECK(field.weight_factor(at(query, x, -y), 1) == Approx(1.0f).margin(1e-5));
    }
}

TEST_CASE("gamma = 1 with no line gives the same strands as no parting", "[parting]") {
  const Mesh mesh = make_grid(20);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(
      query, {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {-0.5f, 0.5f, 0}, {0.5f, 0.5f, 0}, {0.05f, 0.1f, 0}});
  // A line whose points all snap to one vertex cuts no edge: there is no line on the surface.
  PartingSettings settings;
  PartingLine line;
  line.name = "dot";
  line.gamma = 1.0f;
  line.points = {{0.3f, 0.3f, 0.0f}, {0.301f, 0.3f, 0.0f}, {0.3f, 0.301f, 0.0f}};
  settings.lines.push_back(line);
  const PartingField field(mesh, guides, settings);
  const Roots roots = scatter_roots(mesh, 300, 7);
  for (size_t r = 0; r < roots.size(); ++r)
    for (size_t g = 0; g < guides.size(); ++g) REQUIRE(field.weight_factor(roots.points[r], g) == 1.0f);

  for (const auto method : {InterpolationSettings::Method::streamline, InterpolationSettings::Method::fur}) {
    InterpolationSettings interpolation;
    interpolation.method = method;
    const Binding plain = bind(mesh, guides, roots, interpolation, nullptr);
    const Binding parted = bind(mesh, guides, roots, interpolation, &field);
    GrowOptions options;
    options.points_per_strand = 8;
    StrandSet a, b;
    grow(plain, mesh, query, roots, guides.strands, options, a);
    grow(parted, mesh, query, roots, guides.strands, options, b);
    REQUIRE(a.positions.size() == b.positions.size());
    for (size_t p = 0; p < a.positions.size(); ++p) REQUIRE(a.positions[p] == b.positions[p]);
  }
}

TEST_CASE("hard zones from face groups: no root is influenced by a guide of another zone", "[parting]") {
  const Mesh mesh = make_grid(20);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, -0.5f, 0},
                                                     {-0.5f, 0.5f, 0},
                                                     {-0.05f, 0.0f, 0},
                                                     {0.5f, -0.5f, 0},
                                                     {0.5f, 0.5f, 0},
                                                     {0.05f, 0.0f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::face_groups;
  const PartingField field(mesh, guides, settings);
  REQUIRE(field.zone_count() == 2);
  CHECK(field.guide_zone(0) == field.guide_zone(2));
  CHECK(field.guide_zone(2) != field.guide_zone(5));
  CHECK(field.zone_name(field.zone_of(at(query, 0.7f, 0.2f))).find("right") != std::string::npos);
  CHECK(field.weight_factor(at(query, 0.02f, 0.0f), 2) == 0.0f);
  CHECK(field.weight_factor(at(query, -0.02f, 0.0f), 2) == 1.0f);

  const Roots roots = scatter_roots(mesh, 2000, 3);
  InterpolationSettings interpolation;
  interpolation.k = 4;
  const Binding parted = bind(mesh, guides, roots, interpolation, &field);
  CHECK(cross_zone_slots(field, roots, parted) == 0);
  // Without the zones the same roots do use guides across the boundary: the count can fail.
  const Binding plain = bind(mesh, guides, roots, interpolation, nullptr);
  CHECK(cross_zone_slots(field, roots, plain) > 100);
}

TEST_CASE("a hard parting line reaching the border cuts the surface into zones", "[parting]") {
  const Mesh mesh = make_grid(20);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{0.0f, -0.5f, 0}, {0.0f, 0.5f, 0}, {0.6f, 0.0f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::lines;
  PartingLine line;
  line.name = "crown";
  line.hard = true;
  for (int i = 0; i <= 10; ++i) line.points.emplace_back(0.3f, -1.0f + 0.2f * float(i), 0.0f);
  settings.lines.push_back(line);
  const PartingField field(mesh, guides, settings);
  REQUIRE(field.zone_count() == 2);
  CHECK(field.guide_zone(0) == field.guide_zone(1));
  CHECK(field.guide_zone(0) != field.guide_zone(2));
  CHECK(field.zone_of(at(query, 0.25f, 0.9f)) == field.guide_zone(0));
  CHECK(field.zone_of(at(query, 0.35f, -0.9f)) == field.guide_zone(2));

  const Roots roots = scatter_roots(mesh, 1500, 11);
  const Binding parted = bind(mesh, guides, roots, InterpolationSettings{}, &field);
  CHECK(cross_zone_slots(field, roots, parted) == 0);
  CHECK(cross_zone_slots(field, roots, bind(mesh, guides, roots, InterpolationSettings{}, nullptr)) > 100);
}

TEST_CASE("a hard parting line that separates nothing is an error naming it", "[parting]") {
  const Mesh mesh = make_grid(20);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{0.0f, -0.5f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::lines;
  settings.lines.push_back(straight_line(-0.5f, 0.5f, 2.0f, true));
  settings.lines.back().loc = FileLoc{"head.groom.yaml", 14, 7};
  const std::string message = message_of([&] { PartingField field(mesh, guides, settings); });
  CHECK(message.find("head.groom.yaml:14:7") != std::string::npos);
  CHECK(message.find("'hard line'") != std::string::npos);
}

TEST_CASE("a zone with roots and no guide is an error naming the zone", "[parting]") {
  const Mesh mesh = make_grid(20);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, -0.5f, 0}, {-0.5f, 0.5f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::face_groups;
  const PartingField field(mesh, guides, settings);
  const Roots roots = scatter_roots(mesh, 200, 5);
  const std::string direct = message_of([&] { field.check_roots_have_guides(roots.points); });
  CHECK(direct.find("face group 'right'") != std::string::npos);
  const std::string from_bind = message_of([&] { bind(mesh, guides, roots, InterpolationSettings{}, &field); });
  CHECK(from_bind.find("'right'") != std::string::npos);
  // Roots only where the guides are: fine.
  std::vector<bool> left(mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) left[t] = mesh.triangle_groups[t] == 0;
  CHECK_NOTHROW(field.check_roots_have_guides(scatter_roots(mesh, 200, 5, left).points));
}

TEST_CASE("zones from a zone map file, with located errors", "[parting]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}, {0.5f, 0.0f, 0}});
  const auto dir = std::filesystem::temp_directory_path() / "plume_parting_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "zones.txt").string();
  {
    std::ofstream out(path);
    out << "# one zone id per triangle\n";
    for (size_t t = 0; t < mesh.triangle_count(); ++t) out << (mesh.triangle_groups[t] == 0 ? 7 : 3) << "\n";
  }
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::zone_map;
  settings.zone_map_path = path;
  const PartingField field(mesh, guides, settings);
  REQUIRE(field.zone_count() == 2);
  CHECK(field.zone_name(field.guide_zone(0)) == "zone map id 7");
  CHECK(field.zone_name(field.guide_zone(1)) == "zone map id 3");
  // A zone with roots and no guide names the groom's partings, the zone and the map file.
  settings.loc = FileLoc{"head.groom.yaml", 12, 3};
  const Guides left_only = make_standing_guides(query, {{-0.5f, 0.0f, 0}});
  const PartingField one_sided(mesh, left_only, settings);
  CHECK(message_of([&] { one_sided.check_roots_have_guides(scatter_roots(mesh, 200, 5).points); }) ==
        "head.groom.yaml:12:3: partings.zones: hard parting zone zone map id 3 (of " + path +
            ") has roots but no guide: add a guide whose root is in it, or keep roots out of it");

  {
    std::ofstream out(path);
    out << "1\n1\nleft\n";
  }
  const std::string bad = message_of([&] { PartingField f(mesh, guides, settings); });
  CHECK(bad.find(path + ":3:1") != std::string::npos);
  {
    std::ofstream out(path);
    out << "1\n1\n";
  }
  const std::string short_map = message_of([&] { PartingField f(mesh, guides, settings); });
  CHECK(short_map.find("has 2 zone ids, the mesh has 200 triangles") != std::string::npos);
  settings.zone_map_path = (dir / "missing.txt").string();
  CHECK(message_of([&] { PartingField f(mesh, guides, settings); }).find("missing.txt") != std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST_CASE("parting settings are validated: unknown group, gamma below 1", "[parting]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}});
  PartingSettings settings;
  settings.zone_source = PartingSettings::ZoneSource::face_groups;
  settings.zone_groups = {"left", "scalp"};
  CHECK(message_of([&] { PartingField f(mesh, guides, settings); }).find("no face group 'scalp'") !=
        std::string::npos);
  PartingSettings partial;
  partial.lines.push_back(straight_line(-0.5f, 0.5f, 0.5f));
  CHECK(message_of([&] { PartingField f(mesh, guides, partial); }).find("gamma must be >= 1") != std::string::npos);
}

TEST_CASE("without partings the field is empty and every factor is 1", "[parting]") {
  const Mesh mesh = make_grid(10);
  const MeshQuery query(mesh);
  const Guides guides = make_standing_guides(query, {{-0.5f, 0.0f, 0}, {0.5f, 0.0f, 0}});
  const PartingField field(mesh, guides, PartingSettings{});
  CHECK(field.empty());
  CHECK(field.zone_count() == 1);
  CHECK(field.zone_of(at(query, 0.3f, 0.3f)) == 0);
  CHECK(field.weight_factor(at(query, 0.3f, 0.3f), 1) == 1.0f);
}
