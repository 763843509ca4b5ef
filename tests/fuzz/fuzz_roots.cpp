// libFuzzer target: a roots file (`.txt`, one x y z per line), read by io::read_points().
#include "fuzz_common.h"
#include "io/point_list.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string path = plume::fuzz::write_input(data, size, "input.txt");
  plume::fuzz::only_input_errors([&] { plume::fuzz::check_points(plume::io::read_points(path)); });
  return 0;
}
