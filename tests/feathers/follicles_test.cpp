// Follicles scattered on the bird by density and tract masks: face groups keep them on their tracts,
// a vertex map thins them where it is low (and keeps a subset of the unthinned follicles, with their
// ids), a density gives a count proportional to the tracts' area. A key feather placed at a point of
// the skin weighs most there, its weight falling off continuously. Each feather's seeded variation
// comes from its stable id, within the groom's bounds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <map>
#include <set>

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

double area_of(const Mesh &mesh, const std::set<int> &groups) {
  double area = 0.0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (!groups.count(mesh.triangle_groups[f])) continue;
    const Eigen::Vector3i &t = mesh.triangles[f];
    const Eigen::Vector3d a = mesh.positions[size_t(t[0])].cast<double>(), b = mesh.positions[size_t(t[1])].cast<double>(),
                          c = mesh.positions[size_t(t[2])].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace

TEST_CASE("follicles keep to their tracts, thin where a vertex map is low, and follow a density", "[feathers]") {
  const Mesh rest = io::read_obj_mesh(kBird + "bird.obj");
  FollicleSettings settings;
  settings.count = 4000;
  settings.groups = {"back", "belly"};
  settings.seed = 11;
  const std::set<int> tracts = {rest.group_index("back"), rest.group_index("belly")};
  REQUIRE(!tracts.count(-1));

  // Only on the tracts.
  const Follicles all = scatter_follicles(rest, settings, {});
  REQUIRE(all.size() == 4000);
  for (const SurfacePoint &p : all.points) REQUIRE(tracts.count(rest.triangle_groups[size_t(p.triangle)]));

  // A vertex map: 0 on the bird's left (x > 0), 1 on its right; then 0.5 everywhere.
  std::vector<float> sided(rest.vertex_count());
  for (size_t v = 0; v < sided.size(); ++v) sided[v] = rest.positions[v].x() > 0.0f ? 0.0f : 1.0f;
  const Follicles right = scatter_follicles(rest, settings, sided);
  CHECK(right.size() > 1000);
  CHECK(right.size() < all.size());
  const std::set<uint64_t> all_ids(all.ids.begin(), all.ids.end());
  for (size_t i = 0; i < right.size(); ++i) {
    INFO("follicle " << right.ids[i]);
    // Kept ones are the unthinned follicles themselves (same id, same place), none where the map is 0.
    REQUIRE(all_ids.count(right.ids[i]));
    const Eigen::Vector3i &t = rest.triangles[size_t(right.points[i].triangle)];
    const float value = right.points[i].bary[0] * sided[size_t(t[0])] + right.points[i].bary[1] * sided[size_t(t[1])] +
                        right.points[i].bary[2] * sided[size_t(t[2])];
    REQUIRE(value > 0.0f);
  }
  const Follicles half = scatter_follicles(rest, settings, std::vector<float>(rest.vertex_count(), 0.5f));
  CHECK(double(half.size()) == Approx(0.5 * double(all.size())).epsilon(0.06));
  for (const uint64_t id : half.ids) REQUIRE(all_ids.count(id));
  CHECK(scatter_follicles(rest, settings, std::vector<float>(rest.vertex_count(), 1.0f)).ids == all.ids);
  CHECK(scatter_follicles(rest, settings, std::vector<float>(rest.vertex_count(), 0.0f)).size() == 0);

  // A density: follicles per unit of area on the tracts.
  FollicleSettings dense = settings;
  dense.count = 0;
  dense.density = 20.0;
  const double expected = 20.0 * area_of(rest, tracts);
  CHECK(double(scatter_follicles(rest, dense, {}).size()) == Approx(expected).epsilon(0.02));
}

TEST_CASE("a key feather at a point weighs most there and falls off continuously along the skin", "[feathers]") {
  const GroomDesc groom = io::read_groom_file(kBird + "bird.groom.yaml");
  Mesh rest = io::read_obj_mesh(kBird + "bird.obj");
  rest.compute_normals();
  const MeshQuery query(rest);
  // A flight feather placed on the middle of the back, among the back's contour feathers.
  FeatherDesc desc = groom.feathers;
  const int back = rest.group_index("back");
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  int count = 0;
  for (size_t f = 0; f < rest.triangles.size(); ++f)
    if (rest.triangle_groups[f] == back) {
      centre += surface_position(rest, SurfacePoint{int32_t(f), Eigen::Vector3f::Constant(1.0f / 3.0f)});
      ++count;
    }
  centre /= float(count);
  KeyFeather key;
  key.template_name = "flight";
  for (size_t t = 0; t < desc.templates.size(); ++t)
    if (desc.templates[t].name == "flight") key.template_index = int(t);
  REQUIRE(key.template_index >= 0);
  key.point = surface_position(rest, query.closest(centre));
  key.radius = 1.5f;
  desc.key_feathers.push_back(key);
  const KeyFeatherField field(rest, desc);
  const size_t k = field.key_count() - 1;
  std::vector<float> w(field.key_count()), previous(field.key_count());

  // At the point it outweighs the back's contour key feather, whose tract holds the point.
  field.weights(query.closest(key.point), w);
  CHECK(field.distance(k, query.closest(key.point)) < 1e-3);
  CHECK(w[k] > 0.4f);
  CHECK(w[k] == *std::max_element(w.begin(), w.end()));
  // Along the skin away from it (points 0.02 apart, snapped to the surface): its weight falls, and
  // every weight changes by at most a bound proportional to the step.
  const Eigen::Vector3f direction(0.0f, 0.0f, -1.0f);  // toward the tail
  float last_weight = 2.0f, worst_change = 0.0f;
  bool first = true;
  for (int i = 0; i <= 300; ++i) {
    const SurfacePoint sp = query.closest(key.point + 0.02f * float(i) * direction);
    field.weights(sp, w);
    if (!first)
      for (size_t j = 0; j < w.size(); ++j) worst_change = std::max(worst_change, std::abs(w[j] - previous[j]));
    if (i % 25 == 0) {
      CHECK(w[k] <= last_weight + 1e-4f);
      last_weight = w[k];
    }
    previous = w;
    first = false;
  }
  CHECK(last_weight < 0.05f);
  CHECK(worst_change < 0.05f);
}

TEST_CASE("each feather's variation is seeded by its stable id, within the groom's bounds", "[feathers]") {
  const GroomDesc groom = io::read_groom_file(kBird + "bird.groom.yaml");
  const Mesh rest = io::read_obj_mesh(kBird + "bird.obj");
  const MeshQuery query(rest);
  const Guides stems = bind_guides(query, io::read_strands(kBird + "stems.obj"), "stems.obj");
  FeatherDesc plain = groom.feathers;
  plain.layers = false;
  plain.variation = {};
  FeatherDesc varied = plain;
  varied.variation.length = 0.12f;
  varied.variation.barb_angle = 4.0f;
  varied.variation.stage = 0.3f;
  varied.variation.seed = 3;
  const Follicles few = scatter_follicles(rest, plain.follicles, {}, 300);
  const Follicles more = scatter_follicles(rest, plain.follicles, {}, 600);
  const Coat base(rest, stems, plain, few), coat(rest, stems, varied, few), larger(rest, stems, varied, more);
  std::map<uint64_t, size_t> in_larger;
  for (size_t i = 0; i < larger.size(); ++i) in_larger[larger.ids()[i]] = i;

  double least = 2.0, most = 0.0, least_angle = 0.0, most_angle = 0.0;
  size_t grown_less = 0;
  for (size_t i = 0; i < coat.size(); ++i) {
    INFO("feather " << coat.ids()[i]);
    const FeatherTemplate &a = base.shapes()[i].main, &b = coat.shapes()[i].main;
    // The stage is lowered by up to 0.3, to 0.7 at least: the lengths are the adult's from 0.5 on,
    // and the rachis's curvature grows to the adult's over 0.8 to 1 (feathers/growth.h).
    if (a.curvature_front != 0.0f) {
      REQUIRE(std::abs(b.curvature_front) <= std::abs(a.curvature_front) * (1.0f + 1e-5f));
      grown_less += std::abs(b.curvature_front) < 0.99f * std::abs(a.curvature_front);
    }
    const double scale = double(b.calamus_length + b.rachis_length) / double(a.calamus_length + a.rachis_length);
    least = std::min(least, scale);
    most = std::max(most, scale);
    REQUIRE(scale >= 0.88 - 1e-5);
    REQUIRE(scale <= 1.12 + 1e-5);
    const double angle = double(b.left.angle_base - a.left.angle_base);
    if (a.left.angle_base > 4.0f && a.left.angle_base < 176.0f) {
      REQUIRE(std::abs(angle) <= 4.0 + 1e-4);
      REQUIRE(double(b.right.angle_tip - a.right.angle_tip) == Approx(angle).margin(1e-4));
      least_angle = std::min(least_angle, angle);
      most_angle = std::max(most_angle, angle);
    }
    // The same id in a coat of more follicles gets the same feather.
    const auto found = in_larger.find(coat.ids()[i]);
    REQUIRE(found != in_larger.end());
    const FeatherTemplate &c = larger.shapes()[found->second].main;
    CHECK(c.rachis_length == b.rachis_length);
    CHECK(c.left.angle_base == b.left.angle_base);
  }
  // The bounds are used, both ways.
  CHECK(least < 0.93);
  CHECK(most > 1.07);
  CHECK(least_angle < -2.0);
  CHECK(most_angle > 2.0);
  CHECK(grown_less > coat.size() / 10);
}
