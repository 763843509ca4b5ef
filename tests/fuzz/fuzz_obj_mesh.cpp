// libFuzzer target: an emitter mesh, read by io::read_obj_mesh() (and io::read_obj_file(), which
// `plume info` uses and which tells meshes from strands).
#include "fuzz_common.h"
#include "io/obj_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string path = plume::fuzz::write_input(data, size, "input.obj");
  plume::fuzz::only_input_errors([&] { plume::fuzz::check_mesh(plume::io::read_obj_mesh(path)); });
  plume::fuzz::only_input_errors([&] {
    const plume::io::ObjContents contents = plume::io::read_obj_file(path);
    if (contents.mesh)
      plume::fuzz::check_mesh(*contents.mesh);
    else
      plume::fuzz::check_strands(contents.strands);
  });
  return 0;
}
