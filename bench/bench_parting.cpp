// What the side parting of grooms/sintel_parting does to Sintel's hair: the same roots bound and grown
// with and without the parting line. For roots in bands of distance from the line: the share of their
// weight that comes from guides across the line (guides the line attenuates to below half), and how
// far their strands move (mean over points, % of strand length). A partial parting should act near
// its line and leave the rest of the head alone.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"
#include "groom/groom_scene.h"

using namespace plume;

namespace {

/// Distance from p to a polyline.
float distance_to_polyline(const std::vector<Eigen::Vector3f> &line, const Eigen::Vector3f &p) {
  float best = INFINITY;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector3f a = line[i], ab = line[i + 1] - line[i];
    const float t = ab.squaredNorm() > 0.0f ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f) : 0.0f;
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

}  // namespace

int main() {
  const std::string path = std::string(PLUME_SOURCE_DIR) + "/grooms/sintel_parting/sintel_parting.groom.yaml";
  const test::GroomScene scene(path);
  const GroomDesc &groom = scene.groom;
  const Mesh &mesh = scene.mesh;
  const MeshQuery &query = *scene.query;
  const Guides &guides = scene.guides;
  const Roots &roots = scene.roots;

  const partings::PartingField partings(mesh, guides, groom.partings);
  const interp::Binding plain = interp::bind(mesh, guides, roots, groom.interpolation);
  const interp::Binding parted = interp::bind(mesh, guides, roots, groom.interpolation, &partings);
  interp::GrowOptions options;
  options.points_per_strand = groom.points_per_strand;
  options.with_widths = false;
  StrandSet plain_strands, parted_strands;
  interp::grow(plain, mesh, query, roots, guides.strands, options, plain_strands);
  interp::grow(parted, mesh, query, roots, guides.strands, options, parted_strands);

  const std::vector<Eigen::Vector3f> &line = groom.partings.lines.at(0).points;
  float line_length = 0.0f;
  for (size_t i = 0; i + 1 < line.size(); ++i) line_length += (line[i + 1] - line[i]).norm();
  // Bands in units of the line's length.
  const float edges[] = {0.0f, 0.1f, 0.25f, 0.5f, 1.0f, INFINITY};
  constexpr int band_count = 5;
  struct Band {
    size_t roots = 0;
    double across_plain = 0.0, across_parted = 0.0, moved = 0.0, moved_max = 0.0;
  } bands[band_count];
  const int k = plain.k;
  for (size_t r = 0; r < roots.size(); ++r) {
    const float d = distance_to_polyline(line, surface_position(mesh, roots.points[r])) / line_length;
    int b = 0;
    while (b + 1 < band_count && d >= edges[b + 1]) ++b;
    Band &band = bands[b];
    ++band.roots;
    auto across_share = [&](const interp::Binding &binding) {
      double share = 0.0;
      for (int s = 0; s < k; ++s) {
        const int32_t g = binding.guide_ids[r * size_t(k) + size_t(s)];
        if (g >= 0 && partings.weight_factor(roots.points[r], size_t(g)) < 0.5f)
          share += binding.weights[r * size_t(k) + size_t(s)];
      }
      return share;
    };
    band.across_plain += across_share(plain);
    band.across_parted += across_share(parted);
    double moved = 0.0;
    const auto a = plain_strands.points(r), b_pts = parted_strands.points(r);
    for (size_t i = 0; i < a.size(); ++i) moved += (a[i] - b_pts[i]).norm();
    moved = 100.0 * moved / double(a.size()) / std::max(plain_strands.length(r), 1e-12);
    band.moved += moved;
    band.moved_max = std::max(band.moved_max, moved);
  }

  std::printf("Sintel side parting (%s): %zu roots, %zu guides, line %.2f units long, gamma %.1f, %d threads\n",
              groom.partings.lines[0].name.c_str(), roots.size(), guides.size(), double(line_length),
              double(groom.partings.lines[0].gamma), omp_get_max_threads());
  std::printf("%-22s %7s %22s %22s %12s %12s\n", "distance to the line", "roots", "across-line weight, no",
              "across-line weight, with", "moved mean", "moved max");
  for (int b = 0; b < band_count; ++b) {
    const Band &band = bands[b];
    if (band.roots == 0) continue;
    char label[64];
    if (std::isinf(edges[b + 1]))
      std::snprintf(label, sizeof label, ">= %.2f x length", double(edges[b]));
    else
      std::snprintf(label, sizeof label, "%.2f-%.2f x length", double(edges[b]), double(edges[b + 1]));
    const double n = double(band.roots);
    std::printf("%-22s %7zu %21.1f%% %23.1f%% %11.2f%% %11.2f%%\n", label, band.roots, 100.0 * band.across_plain / n,
                100.0 * band.across_parted / n, band.moved / n, band.moved_max);
  }
  return 0;
}
