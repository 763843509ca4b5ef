// Feathers follow their simulated stems: on the bird, whose left wing opens over frames 1-15, the
// groom's dynamics swing the stems away from where the skin alone carries them, and a feather grown
// on one stem turns as that stem turns (measured on the stems and the rachis curves, not through the
// coat's internals). That `plume regrow` grows from the simulated stems: feather_cli_test.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "feathers/coat.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"

using namespace plume;

namespace {

const std::string kBird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/bird.groom.yaml";

/// Degrees between two directions.
double degrees_between(const Eigen::Vector3f &a, const Eigen::Vector3f &b) {
  const double c = double(a.normalized().dot(b.normalized()));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

/// Per feather of `frame` (one per stem here): its rachis chord, root to tip.
std::vector<Eigen::Vector3f> rachis_chords(const feathers::CoatFrame &frame, size_t feathers) {
  std::vector<Eigen::Vector3f> chords(feathers, Eigen::Vector3f::Zero());
  const StrandSet &c = frame.curves.curves;
  for (size_t s = 0; s < c.strand_count(); ++s)
    if (frame.curves.parts[s] == FeatherPart::rachis && chords[frame.curves.feathers[s]].isZero())
      chords[frame.curves.feathers[s]] = c.points(s).back() - c.points(s).front();
  return chords;
}

/// The point of strand `s` at arc length `length` from its root (its tip beyond its length).
Eigen::Vector3f point_at_length(const StrandSet &strands, size_t s, float length) {
  const auto p = strands.points(s);
  float walked = 0.0f;
  for (size_t i = 1; i < p.size(); ++i) {
    const float segment = (p[i] - p[i - 1]).norm();
    if (walked + segment >= length && segment > 0.0f) return p[i - 1] + (length - walked) / segment * (p[i] - p[i - 1]);
    walked += segment;
  }
  return p.back();
}

/// `v` projected onto the plane across `normal` (unit).
Eigen::Vector3f flat(const Eigen::Vector3f &v, const Eigen::Vector3f &normal) { return v - v.dot(normal) * normal; }

/// Degrees of `v` above the plane across `normal` (unit).
double elevation(const Eigen::Vector3f &v, const Eigen::Vector3f &normal) {
  return std::asin(std::clamp(double(v.normalized().dot(normal)), -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

TEST_CASE("feathers follow their simulated stems, frame by frame", "[feathers]") {
  const GroomDesc groom = io::read_groom_file(kBird);
  REQUIRE(groom.feathers.enabled);
  REQUIRE(groom.dynamics.enabled);
  // A feather groom's stems are stiffer than hair by default (the bird's groom gives none).
  CHECK(groom.dynamics.stiffness.at(0.0f) == Approx(10.0f));
  CHECK(groom.dynamics.stiffness.at(1.0f) == Approx(4.0f));
  CHECK(groom.dynamics.damping == Approx(2.0f));

  // The stems as the feather pipeline gets them (app/feather_pipeline.cpp): from the base pipeline,
  // which grows no strands.
  PipelineOptions options;
  options.strand_count = 0;
  Pipeline simulated(groom, options);
  GroomDesc still_groom = groom;
  still_groom.dynamics.enabled = false;  // the stems carried by the skin alone
  Pipeline carried(still_groom, options);

  // One feather on each stem's root: it takes that stem alone.
  const Mesh &rest = simulated.rest_mesh();
  const Guides &stems = simulated.guides();
  feathers::Follicles on_roots;
  for (size_t s = 0; s < stems.size(); ++s) {
    on_roots.points.push_back(stems.roots[s]);
    on_roots.ids.push_back(s);
  }
  FeatherDesc desc = groom.feathers;
  desc.variation = {};  // no seeded turn: the feather lies along its stem
  const feathers::Coat on_stems(rest, stems, desc, on_roots);

  double largest_swing = 0.0;
  for (int frame = 1; frame <= 14; ++frame) {
    const Mesh posed = simulated.posed_mesh(frame);
    const StrandSet moving = simulated.guides_at(frame, posed);
    const StrandSet still = carried.guides_at(frame, posed);
    REQUIRE(moving.offsets == still.offsets);
    if (frame % 4 != 2) continue;
    INFO("frame " << frame);
    const MeshQuery query(posed);

    // The stems are simulated: they swing away from the carried stems (each stem's tip, as a
    // fraction of its length; frame 2 is the first step after rest).
    double swing = 0.0;
    for (size_t s = 0; s < stems.size(); ++s)
      swing = std::max(swing, double((moving.points(s).back() - still.points(s).back()).norm()) / double(still.length(s)));
    largest_swing = std::max(largest_swing, swing);

    // A feather on one stem turns with it: between the carried and the simulated stems, each
    // feather's rachis turns about the skin normal as its stem does (measured: within 0.6 degrees)
    // and, where the skin pass raised it on neither, rises and falls as its stem does (within 1.6),
    // the stem taken over the feather's length.
    feathers::CoatFrame a, b;
    on_stems.grow(posed, query, moving, a);
    on_stems.grow(posed, query, still, b);
    const std::vector<Eigen::Vector3f> chords_a = rachis_chords(a, stems.size()), chords_b = rachis_chords(b, stems.size());
    double worst_azimuth = 0.0, worst_rise = 0.0, worst_below = 0.0;
    size_t free_feathers = 0;
    double stem_turns = 0.0, feather_turns = 0.0;
    for (size_t s = 0; s < stems.size(); ++s) {
      // Each stem over the feather's length, seen in the skin frame at the root: its azimuth about the
      // skin normal and its elevation above the skin.
      const Eigen::Vector3f normal = a.root_frames[s].normal();
      const float reach = on_stems.shapes()[s].main.calamus_length + on_stems.shapes()[s].main.rachis_length;
      const Eigen::Vector3f sa = point_at_length(moving, s, reach) - moving.points(s).front();
      const Eigen::Vector3f sb = point_at_length(still, s, reach) - still.points(s).front();
      const double stem_azimuth = degrees_between(flat(sa, normal), flat(sb, normal));
      const double feather_azimuth = degrees_between(flat(chords_a[s], normal), flat(chords_b[s], normal));
      worst_azimuth = std::max(worst_azimuth, std::abs(feather_azimuth - stem_azimuth));
      // The skin pass only ever raises a feather: never below its stem.
      worst_below = std::max({worst_below, elevation(sa, normal) - elevation(chords_a[s], normal),
                              elevation(sb, normal) - elevation(chords_b[s], normal)});
      // Where the skin pass raised neither, the feather rises and falls as its stem does.
      if (a.lifts[s] > 0.0f || b.lifts[s] > 0.0f) continue;
      ++free_feathers;
      const double stem_rise = elevation(sa, normal) - elevation(sb, normal);
      const double feather_rise = elevation(chords_a[s], normal) - elevation(chords_b[s], normal);
      worst_rise = std::max(worst_rise, std::abs(feather_rise - stem_rise));
      // How far the feather's tip moves between the two, against how far its stem's point moves.
      stem_turns += degrees_between(sa, sb);
      feather_turns += degrees_between(chords_a[s], chords_b[s]);
    }
    INFO("largest tip swing " << swing << " of the stem's length; worst |feather - stem| turn about the skin normal "
                              << worst_azimuth << " degrees, in elevation " << worst_rise << " degrees; "
                              << free_feathers << " feathers the skin pass left alone turned " << feather_turns
                              << " degrees in all, their stems " << stem_turns << "; a feather below its stem by "
                              << worst_below << " degrees");
    CHECK(worst_azimuth < 2.0);
    CHECK(worst_rise < 3.0);
    CHECK(worst_below < 3.0);
    // In all, those feathers turn as much as their stems (measured: 1.05 to 1.14 times; a feather
    // that ignored its stem would not turn at all).
    CHECK(free_feathers > stems.size() / 2);
    CHECK(stem_turns > 10.0);
    CHECK(feather_turns > 0.8 * stem_turns);
    CHECK(feather_turns < 1.3 * stem_turns);
  }
  // The wing's opening swings some stem's tip by more than 5% of its length.
  CHECK(largest_swing > 0.05);
}
