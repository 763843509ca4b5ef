#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>

#include "dynamics/dynamics_fixtures.h"
#include "dynamics/guide_simulator.h"
#include "groom/mesh_query.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume;

TEST_CASE("the Sintel guides turn with the head inextensible, outside the skin, and swing", "[dynamics]") {
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/";
  Mesh head = io::read_obj_mesh(folder + "sintel.obj");
  head.compute_normals();
  const MeshQuery rest_query(head);
  const Guides guides = bind_guides(rest_query, io::read_strands(folder + "sintel_guides.hair"), "sintel");
  // Joints groomed outside the skin must stay outside (the simulator leaves joints that the
  // groomer put under the skin where they are).
  std::vector<bool> outside(guides.strands.point_count());
  for (size_t p = 0; p < outside.size(); ++p) outside[p] = rest_query.signed_distance(guides.strands.positions[p]) >= 0.0f;
  DynamicsSettings settings;  // the defaults, as the Sintel groom uses them
  settings.enabled = true;
  dynamics::GuideSimulator sim(head, guides, settings);
  sim.reset(head);

  // A 60 degree head turn over half a second about a vertical axis through the head's centre,
  // held for half a second.
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f &p : head.positions) centre += p;
  centre /= float(head.vertex_count());
  double largest_lag = 0.0;
  double deepest = 1e9;
  Mesh posed = head;
  for (int frame = 1; frame <= 24; ++frame) {
    const float turn = float(3.14159265 / 3.0) * std::min(1.0f, frame / 12.0f);
    posed = test::moved_mesh(head, turn, Eigen::Vector3f::Zero(), centre);
    sim.step_frame(posed);
    largest_lag = std::max(largest_lag, test::max_relative_offset(sim.guides(), carry_guides(head, posed, guides)));
    const MeshQuery query(posed);
    const auto x = sim.positions();
    for (size_t g = 0; g < guides.size(); ++g)
      for (int64_t j = guides.strands.offsets[g] + 2; j < guides.strands.offsets[g + 1]; ++j)
        if (outside[j])
          deepest = std::min(deepest, double(query.signed_distance(x[j].cast<float>())));
  }
  INFO("largest lag behind the skin " << largest_lag << " of a guide length; deepest point " << deepest);
  CHECK(test::max_length_error(sim.positions(), guides.strands) <= 1e-6);
  CHECK(largest_lag > 0.02);   // the guides swing behind the turning head
  CHECK(deepest >= -1e-4);     // and stay outside the skin (float query rounding)
}
