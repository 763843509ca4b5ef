// The bird of grooms/bird as the feather benchmarks load it: its groom, its rest mesh (with a query)
// and its guide stems bound to that mesh. Posed frames are read from `folder` + "anim/...".
#pragma once

#include <string>

#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume::bench {

struct Bird {
  std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  GroomDesc groom = io::read_groom_file(folder + "bird.groom.yaml");
  Mesh rest = io::read_obj_mesh(folder + "bird.obj");
  MeshQuery rest_query{rest};  // not copyable: a Bird stays where it is made
  Guides stems = bind_guides(rest_query, io::read_strands(folder + "stems.obj"), "stems.obj");
};

}  // namespace plume::bench
