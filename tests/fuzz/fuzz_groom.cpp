// libFuzzer target: a groom file, read by io::read_groom_file(). The input is written next to
// copies of the files the test grooms name (tests/data/groom_file: head.obj, guides.obj, roots.txt,
// density.txt, zones.txt), so that mutations of a groom that passes get past the file checks.
#include <filesystem>

#include "fuzz_common.h"
#include "io/groom_file.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
  std::vector<std::string> files;
  for (const auto &entry : std::filesystem::directory_iterator(PLUME_TEST_DATA "/groom_file"))
    if (entry.path().extension() != ".yaml") files.push_back(entry.path().string());
  plume::fuzz::work_folder(files);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string path = plume::fuzz::write_input(data, size, "input.groom.yaml");
  plume::fuzz::only_input_errors([&] { plume::fuzz::check_groom(plume::io::read_groom_file(path)); });
  return 0;
}
