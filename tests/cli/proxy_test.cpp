// Proxy runs are subsets of the full groom: a strand regrown with fewer roots (--strands) is the same
// to the bit as in a run with more, effects included (clump centres are chosen in arrival order),
// unless the separation pass is on: then within its largest move.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>

#include "cli/cli_fixtures.h"
#include "groom/strand_set.h"
#include "io/strand_file.h"

using namespace plume::cli_test;

namespace {

/// Strand id -> its points, from a written strand file.
std::map<uint64_t, std::vector<Eigen::Vector3f>> strands_by_id(const std::string &path) {
  const plume::StrandSet strands = plume::io::read_strands(path);
  std::map<uint64_t, std::vector<Eigen::Vector3f>> by_id;
  for (size_t i = 0; i < strands.strand_count(); ++i) {
    const auto points = strands.points(i);
    by_id[strands.ids[i]] = std::vector<Eigen::Vector3f>(points.begin(), points.end());
  }
  return by_id;
}

}  // namespace

TEST_CASE("a proxy's strands are the same to the bit in a run with more roots, effects included", "[cli]") {
  const ScratchDir scratch("proxy_subset");
  // The shipped effects groom with its separation pass turned off (a copy, its files named in full).
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/effects/";
  const std::string groom = scratch / "effects.groom.yaml";
  {
    std::ifstream in(folder + "effects.groom.yaml");
    std::ofstream out(groom);
    size_t turned_off = 0;
    for (std::string line; std::getline(in, line);) {
      if (const size_t at = line.find("separate: true"); at != std::string::npos) {
        ++turned_off;
        line.replace(at, 14, "separate: false");
      }
      for (const std::string name : {"../sintel/", "frizz_map.txt", "curl_map.txt"})
        if (const size_t at = line.find(name); at != std::string::npos) line.insert(at, folder);
      out << line << "\n";
    }
    REQUIRE(turned_off == 1);
  }
  for (const std::string count : {"500", "1000", "2500"}) {
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 5 --strands " + count + " --out " +
                                        quoted(scratch / ("s" + count + ".####.usda")) + " --preview " +
                                        quoted(scratch / "p.####.png"),
                                    scratch);
    REQUIRE(run.exit_code == 0);
  }
  const auto small = strands_by_id(scratch / "s500.0005.usda");
  const auto medium = strands_by_id(scratch / "s1000.0005.usda");
  const auto large = strands_by_id(scratch / "s2500.0005.usda");
  REQUIRE(small.size() == 500);
  REQUIRE(medium.size() == 1000);
  REQUIRE(large.size() == 2500);
  size_t same = 0, compared = 0;
  for (const auto *subset : {&small, &medium})
    for (const auto &[id, points] : *subset) {
      const auto it = large.find(id);
      REQUIRE(it != large.end());
      ++compared;
      if (it->second.size() == points.size() &&
          std::equal(points.begin(), points.end(), it->second.begin(),
                     [](const Eigen::Vector3f &a, const Eigen::Vector3f &b) { return a == b; }))
        ++same;
    }
  CHECK(same == compared);
}

TEST_CASE("with the separation pass (the shipped effects groom), a proxy's strands are within its largest move of a "
          "run with more roots",
          "[cli]") {
  // The pass parts a strand from the neighbours grown with it, so a proxy's strand may differ from
  // the full run's where a neighbour the proxy lacks came near: by at most the pass's largest move
  // (0.1 of the median segment) before the effects, which carry a strand's difference into the
  // strands clumped to it (a clump's strands follow its centre strand): twice that after them.
  const ScratchDir scratch("proxy_separate");
  const std::string groom = std::string(PLUME_SOURCE_DIR) + "/grooms/effects/effects.groom.yaml";
  for (const std::string count : {"500", "2500"})
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 5 --strands " + count + " --no-preview --out " +
                          quoted(scratch / ("s" + count + ".####.usda")),
                      scratch)
                .exit_code == 0);
  const auto small = strands_by_id(scratch / "s500.0005.usda");
  const auto large = strands_by_id(scratch / "s2500.0005.usda");
  REQUIRE(small.size() == 500);
  REQUIRE(large.size() == 2500);
  const double median = plume::median_segment_length(plume::io::read_strands(scratch / "s2500.0005.usda"));
  size_t same = 0;
  float worst = 0.0f;
  for (const auto &[id, points] : small) {
    const auto it = large.find(id);
    REQUIRE(it != large.end());
    REQUIRE(it->second.size() == points.size());
    float apart = 0.0f;
    for (size_t j = 0; j < points.size(); ++j) apart = std::max(apart, (points[j] - it->second[j]).norm());
    worst = std::max(worst, apart);
    same += apart == 0.0f;
  }
  INFO(same << " of 500 strands the same to the bit, the farthest point " << worst / median << " median segments away");
  CHECK(double(worst) <= 2.0 * 0.1 * median);
  CHECK(same >= 450);  // only where a neighbour came near
}
