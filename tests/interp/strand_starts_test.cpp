// interp::strand_starts: each strand's first point without growing it, which `plume check --groom`
// matches a strand file's roots with. It must be the first point grow() writes, to the bit, for every
// method, with and without the separation pass, on roots at guide roots (the guide's own curve),
// among hovering guides (lifted roots), over partings, and at tiny and huge scales.
#include <catch2/catch.hpp>
#include <cstring>

#include "interp/hard_scenes.h"
#include "interp/scene_measures.h"
#include "partings/parting_field.h"

using namespace plume;
using namespace plume::test;
using Method = InterpolationSettings::Method;

namespace {

/// The scene's roots, then its guides' roots (strands that are their guide).
Roots roots_and_guide_roots(const Scene &scene) {
  Roots roots = scene.roots;
  const Roots at_guides = roots_of(scene.guides);
  for (size_t g = 0; g < at_guides.size(); ++g) {
    roots.points.push_back(at_guides.points[g]);
    roots.ids.push_back(uint64_t(scene.roots.size() + g));
  }
  return roots;
}

/// How many roots' starts differ, bit for bit, from the first points grow() writes.
size_t starts_differing(const Scene &scene, Method method, bool separate,
                        const partings::PartingField *partings = nullptr) {
  const Roots roots = roots_and_guide_roots(scene);
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, roots, settings_of(method), partings);
  interp::GrowOptions options;
  options.points_per_strand = 12;
  options.separate = separate && method == Method::streamline;
  StrandSet strands;
  interp::grow(binding, scene.mesh, *scene.query, roots, scene.guides.strands, options, strands);
  const std::vector<Eigen::Vector3f> starts =
      interp::strand_starts(binding, scene.mesh, *scene.query, roots, scene.guides.strands);
  REQUIRE(starts.size() == strands.strand_count());
  size_t differing = 0;
  for (size_t s = 0; s < starts.size(); ++s)
    if (std::memcmp(starts[s].data(), strands.points(s).front().data(), sizeof(Eigen::Vector3f)) != 0) ++differing;
  return differing;
}

}  // namespace

TEST_CASE("strand_starts gives the first point grow writes, to the bit, on hard scenes and every method", "[interp]") {
  std::vector<Scene> scenes;
  scenes.push_back(planar_arch(12, 30));
  scenes.push_back(combed_layers(12, 120));
  scenes.push_back(ringlets(24, 60));
  scenes.push_back(draped_sphere(12, 120));
  scenes.push_back(random_flow(7, 12, 12, 80));
  scenes.push_back(scaled(combed_layers(12, 120), 0.01f));
  scenes.push_back(scaled(random_flow(8, 12, 12, 80), 100.0f));
  for (const Scene &scene : scenes)
    for (const Method method : {Method::streamline, Method::fur, Method::linear})
      for (const bool separate : {false, true}) {
        if (separate && method != Method::streamline) continue;
        INFO(scene.name << ", method " << int(method) << (separate ? ", separation pass" : ""));
        CHECK(starts_differing(scene, method, separate) == 0);
      }
}

TEST_CASE("strand_starts over partings, and its inputs checked as grow's", "[interp]") {
  for (const bool hard : {true, false}) {
    PartingSettings settings;
    const Scene scene = parted_sphere(hard, settings, 12, 150);
    const partings::PartingField field(scene.mesh, scene.guides, settings);
    INFO(scene.name);
    CHECK(starts_differing(scene, Method::streamline, false, &field) == 0);
  }
  const Scene scene = planar_arch(12, 10);
  const interp::Binding binding =
      interp::bind(scene.mesh, scene.guides, scene.roots, settings_of(Method::streamline));
  Roots fewer = scene.roots;
  fewer.points.pop_back();
  fewer.ids.pop_back();
  CHECK_THROWS_AS(interp::strand_starts(binding, scene.mesh, *scene.query, fewer, scene.guides.strands), InputError);
  StrandSet broken = scene.guides.strands;
  broken.positions[3].x() = NAN;
  CHECK_THROWS_AS(interp::strand_starts(binding, scene.mesh, *scene.query, scene.roots, broken), InputError);
}
