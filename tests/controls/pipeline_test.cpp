// The controls in the pipeline, on the shipped control grooms: strands out of the skin on the
// frames they render, a frame produced alone equal to the same frame of a sequence, the same bytes
// on 1 and 2 threads, and the dynamic blend's two ends equal to the rig and to the simulation.
#include <catch2/catch.hpp>

#include <omp.h>

#include <cstring>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "check/check.h"
#include "controls/control_rig.h"
#include "controls_fixtures.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"

using namespace plume;
using plume::test::same_bits;

namespace {

std::string groom_path(const std::string &name) { return std::string(PLUME_SOURCE_DIR) + "/grooms/" + name; }

// Largest relative change of a segment length from the rest guides.
double max_length_change(const StrandSet &rest, const StrandSet &posed) {
  double worst = 0.0;
  for (size_t g = 0; g < rest.strand_count(); ++g)
    for (size_t j = 1; j < rest.points(g).size(); ++j) {
      const double a = (rest.points(g)[j] - rest.points(g)[j - 1]).norm();
      const double b = (posed.points(g)[j] - posed.points(g)[j - 1]).norm();
      worst = std::max(worst, std::abs(a - b) / a);
    }
  return worst;
}

bool same_frame(const FrameResult &a, const FrameResult &b) {
  return same_bits(a.guides, b.guides) && same_bits(a.strands, b.strands) && a.strands.widths == b.strands.widths;
}

}  // namespace

TEST_CASE(
    "the shipped control grooms keep every strand out of the skin and every guide its length on the frames "
    "they render",
    "[controls]") {
  struct Shipped {
    std::string path;
    std::vector<int> frames;  // increasing: a simulation steps through them
    int64_t strands;          // -1: the groom's own
  };
  auto every = [](int first, int last) {
    std::vector<int> frames;
    for (int f = first; f <= last; ++f) frames.push_back(f);
    return frames;
  };
  const Shipped grooms[] = {
      {groom_path("hedgehog/hedgehog.groom.yaml"), every(1, 24), -1},
      {groom_path("cat/cat.groom.yaml"), {1, 5, 8, 11, 14, 18, 24}, 6000},
      {groom_path("crest/crest.groom.yaml"), every(1, 36), -1},
  };
  for (const Shipped &shipped : grooms) {
    const GroomDesc groom = io::read_groom_file(shipped.path);
    REQUIRE_FALSE(groom.controls.empty());
    PipelineOptions options;
    options.strand_count = shipped.strands;
    Pipeline pipeline(groom, options);
    for (const int frame : shipped.frames) {
      const FrameResult result = pipeline.produce(frame);
      const MeshQuery query(result.mesh);
      std::vector<uint64_t> examples;
      INFO(shipped.path << ", frame " << frame);
      CHECK(check::count_points_inside(result.strands, query, 0.0f, 8, examples) == 0);
      CHECK(max_length_change(pipeline.guides().strands, result.guides) < 1e-4);
      // Grown at the guides' own roots, each strand is its posed guide (the turn keeps the root),
      // within 0.1% of the guide's length, as the checker asks.
      if (groom.roots.source != RootSettings::Source::file) continue;
      REQUIRE(result.strands.strand_count() == result.guides.strand_count());
      double worst = 0.0;
      for (size_t g = 0; g < result.guides.strand_count(); ++g) {
        // Points paired by the fraction of arc length from the root.
        const auto guide = result.guides.points(g), strand = result.strands.points(g);
        const double guide_length = result.guides.length(g), strand_length = result.strands.length(g);
        double along = 0.0;
        for (size_t j = 0; j < strand.size(); ++j) {
          if (j > 0) along += (strand[j] - strand[j - 1]).norm();
          double wanted = along / strand_length * guide_length, walked = 0.0;
          Eigen::Vector3f on_guide = guide.back();
          for (size_t k = 1; k < guide.size(); ++k) {
            const double segment = (guide[k] - guide[k - 1]).norm();
            if (walked + segment >= wanted) {
              const float t = segment > 0.0 ? float((wanted - walked) / segment) : 0.0f;
              on_guide = guide[k - 1] + t * (guide[k] - guide[k - 1]);
              break;
            }
            walked += segment;
          }
          worst = std::max(worst, (strand[j] - on_guide).norm() / guide_length);
        }
      }
      CHECK(worst < 1e-3);
    }
  }
}

TEST_CASE("a frame produced alone equals the same frame of a sequence, and 1 and 2 threads give the same bytes",
          "[controls]") {
  // The cat simulates (the frame alone is simulated from the start again); the crest is rigid.
  for (const auto &[name, frame] :
       {std::pair<std::string, int>{"cat/cat.groom.yaml", 9}, {"crest/crest.groom.yaml", 13}}) {
    const GroomDesc groom = io::read_groom_file(groom_path(name));
    PipelineOptions options;
    options.strand_count = 2000;
    omp_set_num_threads(2);
    // Only the guides carry state from one frame to the next: produce() is posed_mesh() and
    // guides_at(), then growth and effects from the binding and stack fixed at construction. The
    // frames before are stepped as produce() steps them; their strands, which nothing reads, are
    // not grown.
    Pipeline sequence(groom, options);
    for (int f = 1; f < frame; ++f) sequence.guides_at(f, sequence.posed_mesh(f));
    const FrameResult in_sequence = sequence.produce(frame);
    Pipeline alone(groom, options);
    const FrameResult by_itself = alone.produce(frame);
    INFO(name);
    CHECK(same_frame(in_sequence, by_itself));
    omp_set_num_threads(1);
    Pipeline single(groom, options);
    const FrameResult one_thread = single.produce(frame);
    omp_set_num_threads(2);
    CHECK(same_frame(in_sequence, one_thread));
  }
}

TEST_CASE(
    "dynamic blend: 0 gives the rig-driven guides, and controls at amount 0 with a full blend give the "
    "simulation without controls, to the bit",
    "[controls]") {
  const GroomDesc cat = io::read_groom_file(groom_path("cat/cat.groom.yaml"));
  PipelineOptions options;
  options.strand_count = 0;
  const int frame = 10;
  auto guides_at = [&](const GroomDesc &groom) {
    Pipeline pipeline(groom, options);
    StrandSet guides;
    for (int f = 1; f <= frame; ++f) guides = pipeline.guides_at(f, pipeline.posed_mesh(f));
    return guides;
  };

  // Blend 0: the simulation is not mixed in; the guides are those of the same controls without dynamics.
  GroomDesc rig_only = cat;
  for (ControlDesc &c : rig_only.controls.controls) c.dynamic_blend = Keyed<float>::constant(0.0f);
  GroomDesc no_dynamics = rig_only;
  no_dynamics.dynamics.enabled = false;
  for (ControlDesc &c : no_dynamics.controls.controls) c.dynamic_blend = {};
  // (A guide the controls drive only in part keeps the rest of its share of the simulation.)
  const StrandSet rig = guides_at(rig_only), kinematic = guides_at(no_dynamics);
  const Pipeline rest(cat, options);
  const controls::ControlRig control_rig(rest.rest_mesh(), rest.guides(), cat.controls);
  size_t full = 0;
  for (size_t g = 0; g < rig.strand_count(); ++g) {
    if (control_rig.binding().total_weight(g) != 1.0f) continue;
    ++full;
    CHECK(std::memcmp(rig.points(g).data(), kinematic.points(g).data(), rig.points(g).size_bytes()) == 0);
  }
  CHECK(full > 200);
  CHECK(max_length_change(rest.guides().strands, rig) < 5e-5);

  // Every amount 0, blend 1 from root to tip: the simulation of the groom without controls.
  GroomDesc idle = cat;
  for (ControlDesc &c : idle.controls.controls) {
    for (Keyed<float> *k : {&c.lift, &c.aim, &c.direction, &c.random_twist})
      if (!k->empty()) *k = Keyed<float>::constant(0.0f);
    c.offset = {};
    c.dynamic_blend = Keyed<float>::constant(1.0f);
    c.blend_ramp = Ramp{};
  }
  GroomDesc without = cat;
  without.controls = {};
  const StrandSet simulated = guides_at(without);
  CHECK(same_bits(guides_at(idle), simulated));

  // The groom as shipped: roots with the rig, tips toward the simulation, lengths kept.
  const StrandSet blended = guides_at(cat);
  CHECK_FALSE(same_bits(blended, rig));
  CHECK(max_length_change(rest.guides().strands, blended) < 1e-4);
}
