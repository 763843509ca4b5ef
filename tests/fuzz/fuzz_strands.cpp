// libFuzzer target: a strand file of the format PLUME_FUZZ_EXTENSION names (".hair", ".ply",
// ".usda" or ".obj"), read by io::read_strands(), the reader every command uses for guides, caches
// and strands. Built once per format (and twice for PLY, seeded with ascii and with binary files).
#include "fuzz_common.h"
#include "io/strand_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string path = plume::fuzz::write_input(data, size, std::string("input") + PLUME_FUZZ_EXTENSION);
  plume::fuzz::only_input_errors([&] { plume::fuzz::check_strands(plume::io::read_strands(path)); });
  return 0;
}
