// Proxy runs are subsets of the full groom: a strand regrown with fewer roots (--strands) is the same
// to the bit as in a run with more, effects included (clump centres are chosen in arrival order).
#include <catch2/catch.hpp>

#include <map>

#include "cli/cli_fixtures.h"
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
  const std::string groom = std::string(PLUME_SOURCE_DIR) + "/grooms/effects/effects.groom.yaml";
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
