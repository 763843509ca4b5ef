// Follicles scattered on the bird by density and tract masks: face groups keep them on their tracts,
// a vertex map thins them where it is low (and keeps a subset of the unthinned follicles, with their
// ids), a density gives a count proportional to the tracts' area. And a key feather placed at a point
// of the skin weighs most there, its weight falling off continuously.
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

#include "feathers/coat.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"

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
