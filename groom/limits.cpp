#include "groom/limits.h"

#include <cstdio>

namespace plume {

std::string out_of_bounds_message(const Eigen::Vector3f &p) {
  char text[160];
  std::snprintf(text, sizeof text, "expected coordinates within [-%g, %g], got (%g, %g, %g)", double(max_coordinate),
                double(max_coordinate), double(p.x()), double(p.y()), double(p.z()));
  return text;
}

}  // namespace plume
