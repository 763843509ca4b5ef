// Regrows one frame of a groom with Plume's library API and writes the strands:
//   regrow_one_frame GROOM STRANDS FRAME OUT
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "app/pipeline.h"
#include "io/groom_file.h"
#include "io/strand_file.h"

int main(int argc, char **argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: regrow_one_frame GROOM STRANDS FRAME OUT\n");
    return 2;
  }
  try {
    const plume::GroomDesc groom = plume::io::read_groom_file(argv[1]);
    plume::PipelineOptions options;
    options.strand_count = std::atoll(argv[2]);
    plume::Pipeline pipeline(groom, options);
    const plume::FrameResult frame = pipeline.produce(std::atoi(argv[3]));
    plume::io::write_strands(argv[4], frame.strands);
    std::printf("%zu strands, %zu points\n", frame.strands.strand_count(), frame.strands.point_count());
  } catch (const plume::InputError &e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
