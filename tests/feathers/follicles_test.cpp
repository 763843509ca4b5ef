// Follicles scattered on the bird by density and tract masks: face groups keep them on their tracts,
// a vertex map thins them where it is low (and keeps a subset of the unthinned follicles, with their
// ids), a density gives a count proportional to the tracts' area.
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

#include "feathers/coat.h"
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
