// The crest grown as feathers (grooms/crest/crest_feathers.groom.yaml): the controls pose the stems,
// and one feather on each stem follows it. Independent of the coat's code: each feather's rachis is
// compared with its own posed stem, and its vane points with the posed skin.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "feathers/coat.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/strand_file.h"

using namespace plume;

namespace {

const std::string kCrest = std::string(PLUME_SOURCE_DIR) + "/grooms/crest/";

/// Degrees between two directions.
double degrees_between(const Eigen::Vector3f &a, const Eigen::Vector3f &b) {
  const double c = double(a.normalized().dot(b.normalized()));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

TEST_CASE("the crest's feathers follow the stems its controls pose, and stay above the skin", "[controls][feathers]") {
  const GroomDesc groom = io::read_groom_file(kCrest + "crest_feathers.groom.yaml");
  REQUIRE(groom.feathers.enabled);
  REQUIRE_FALSE(groom.controls.empty());
  PipelineOptions options;
  options.strand_count = 0;
  Pipeline pipeline(groom, options);
  const Mesh &rest = pipeline.rest_mesh();
  const MeshQuery rest_query(rest);
  // One follicle at each stem's root (the file's order): feather f grows on stem f.
  const StrandSet stem_file = io::read_strands(kCrest + "crest.hair");
  feathers::Follicles follicles;
  for (size_t s = 0; s < stem_file.strand_count(); ++s) {
    follicles.points.push_back(rest_query.closest(stem_file.points(s)[0]));
    follicles.ids.push_back(s);
  }
  const feathers::Coat coat(rest, pipeline.guides(), groom.feathers, follicles);

  // Lying back (lift 0) at frame 6, raised (lift 1) at 11 and 20, low (0.15) at 27, raised again at 35.
  std::vector<double> mean_rise;
  for (const int frame : {6, 11, 20, 27, 35}) {
    INFO("frame " << frame);
    const Mesh posed = pipeline.posed_mesh(frame);
    const StrandSet stems = pipeline.guides_at(frame, posed);
    const MeshQuery query(posed);
    feathers::CoatFrame grown;
    coat.grow(posed, query, stems, grown);
    REQUIRE(grown.root_frames.size() == stems.strand_count());

    // Each feather's rachis leaves its stem's root along its stem, the whole shaft within a few
    // degrees of the stem's chord.
    double worst_degrees = 0.0, rise = 0.0;
    size_t rachis_count = 0;
    for (size_t c = 0; c < grown.curves.curves.strand_count(); ++c) {
      if (grown.curves.parts[c] != FeatherPart::rachis) continue;
      const uint32_t f = grown.curves.feathers[c];
      const auto rachis = grown.curves.curves.points(c);
      const auto stem = stems.points(f);
      CHECK((rachis.front() - stem.front()).norm() < 0.05f * stems.length(f));
      worst_degrees = std::max(worst_degrees, degrees_between(rachis.back() - rachis.front(), stem.back() - stem.front()));
      // How far the shaft's tip stands from the skin, per unit of its length.
      rise += double(query.signed_distance(rachis.back())) / double(stems.length(f));
      ++rachis_count;
    }
    CHECK(rachis_count == stems.strand_count());
    CHECK(worst_degrees < 20.0);
    mean_rise.push_back(rise / double(rachis_count));

    // No vane point below the posed skin (the independent signed distance).
    size_t below = 0;
    for (const Eigen::Vector3f &p : grown.vanes.positions) below += query.signed_distance(p) < 0.0f;
    CHECK(below == 0);
  }
  // Raised stems raise the feathers: the tips stand further from the skin at lift 1 than at 0 and 0.15.
  CHECK(mean_rise[1] > mean_rise[0] + 0.1);
  CHECK(mean_rise[2] > mean_rise[0] + 0.1);
  CHECK(mean_rise[3] < mean_rise[2] - 0.1);
  CHECK(mean_rise[4] > mean_rise[3] + 0.05);
}
