// Writes the .usda files that the usd_external tests load with tinyusdz:
//   write_sample_usda GUIDES.hair OUT_DIR
// OUT_DIR/guides.usda: the guides as read, per-vertex widths, no time code, every strand in group 0.
// OUT_DIR/animated.usda: 30 strands x 5 points at time code 12, constant width, root UVs, three
// hair groups of 10 strands (groom_group_id) and stable ids beyond 32 bits (int64 plume_id).
#include <cstdio>
#include <string>

#include "groom/error.h"
#include "io/strand_file.h"

int main(int argc, char **argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_sample_usda GUIDES.hair OUT_DIR\n");
    return 2;
  }
  try {
    plume::StrandSet guides = plume::io::read_strands(argv[1]);
    guides.widths.assign(guides.point_count(), 0.0f);
    for (size_t s = 0; s < guides.strand_count(); ++s)
      for (int64_t p = guides.offsets[s]; p < guides.offsets[s + 1]; ++p)
        guides.widths[p] = 0.02f * float(guides.offsets[s + 1] - p) / float(guides.points_in(s));
    plume::io::StrandWriteOptions options;
    options.comment = "Sintel guides (CC-BY 3.0, Blender Foundation)";
    plume::io::write_strands(std::string(argv[2]) + "/guides.usda", guides, options);

    plume::StrandSet animated;
    plume::io::StrandWriteOptions animated_options;
    for (int s = 0; s < 30; ++s) {
      std::vector<Eigen::Vector3f> points;
      for (int p = 0; p < 5; ++p) points.emplace_back(0.1f * float(s), 0.25f * float(p), 0.01f * float(p * p));
      animated.append(points, (uint64_t(s) << 24) * 5952u + uint64_t(s));
      animated_options.root_uvs.emplace_back(float(s) / 30.0f, 0.5f);
      animated_options.group_ids.push_back(s / 10);
    }
    animated_options.time_code = 12.0;
    animated_options.constant_width = 0.005f;
    plume::io::write_strands(std::string(argv[2]) + "/animated.usda", animated, animated_options);
  } catch (const std::exception &error) {
    std::fprintf(stderr, "write_sample_usda: %s\n", error.what());
    return 1;
  }
  return 0;
}
