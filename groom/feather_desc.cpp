#include "groom/feather_desc.h"

#include <cstdio>

namespace plume {

std::vector<float> barb_positions(const FeatherTemplate &f) {
  std::vector<float> positions;
  if (!(f.rachis_length > 0.0f) || !(f.spacing_base > 0.0f) || !(f.spacing_tip > 0.0f)) return positions;
  // t_{k+1} = t_k + spacing(t_k) / r_l, the spacing linear in t from base to tip.
  const double a = double(f.spacing_base) / double(f.rachis_length);
  const double b = double(f.spacing_tip - f.spacing_base) / double(f.rachis_length);
  // The last barb must be clearly below the tip: a barb within 1e-5 of it would come and go with the
  // rounding of the spacing over the length (a groom scaled to millimetres must keep its barbs).
  double t = 0.0;
  while (t < 1.0 - 1e-5) {
    if (positions.size() >= size_t(max_barbs_per_vane)) {
      char length[32];
      std::snprintf(length, sizeof length, "%g", double(f.rachis_length));
      throw InputError(f.loc, "feather template \"" + f.name + "\": barbs.spacing: expected at most " +
                                  std::to_string(max_barbs_per_vane) + " barbs per vane over the rachis length " +
                                  length + ", got more");
    }
    positions.push_back(float(t));
    t += a + b * t;
  }
  return positions;
}

}  // namespace plume
