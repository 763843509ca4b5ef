#include "feathers/build.h"

namespace plume::feathers {

FeatherCounts feather_counts(const FeatherShape &shape, const FeatherDetail &detail) {
  FeatherCounts counts;
  const int64_t vane_vertices = int64_t(detail.vane_rows) * (detail.vane_columns + 1);
  const int64_t vane_triangles = int64_t(detail.vane_rows - 1) * detail.vane_columns * 2;
  auto add_part = [&](const std::vector<float> &positions, bool calamus) {
    const int64_t barbs = 2 * int64_t(positions.size());
    counts.curves += 1 + barbs;
    counts.points += detail.rachis_points + (calamus ? 1 : 0) + barbs * detail.barb_points;
    counts.vane_vertices += 2 * vane_vertices;
    counts.vane_triangles += 2 * vane_triangles;
  };
  add_part(shape.main_positions, true);
  if (shape.has_after) add_part(shape.after_positions, false);
  return counts;
}

FeatherGeometry build_feather(const FeatherShape &shape, const FeatherDetail &detail) {
  const FeatherCounts counts = feather_counts(shape, detail);
  FeatherGeometry g;
  g.curves.positions.resize(size_t(counts.points));
  g.curves.widths.resize(size_t(counts.points));
  g.uv_barb.resize(size_t(counts.points));
  g.uv_vane.resize(size_t(counts.points));
  g.parts.resize(size_t(counts.curves));
  emit_curves(shape, detail, FlatShaft{},
              CurvesOut{g.curves.positions.data(), g.curves.widths.data(), g.uv_barb.data(), g.uv_vane.data(),
                        g.parts.data()});
  // Offsets from the parts' point counts, in emit order.
  g.curves.offsets.assign(1, 0);
  for (const FeatherPart part : g.parts) {
    const bool rachis = part == FeatherPart::rachis || part == FeatherPart::after_rachis;
    const int64_t n = rachis ? detail.rachis_points + (part == FeatherPart::rachis ? 1 : 0) : detail.barb_points;
    g.curves.offsets.push_back(g.curves.offsets.back() + n);
  }
  g.curves.ids.resize(g.parts.size());
  for (size_t c = 0; c < g.parts.size(); ++c) g.curves.ids[c] = c;
  g.vane_positions.resize(size_t(counts.vane_vertices));
  g.vane_uv_barb.resize(size_t(counts.vane_vertices));
  g.vane_uv_vane.resize(size_t(counts.vane_vertices));
  g.vane_triangles.resize(size_t(counts.vane_triangles));
  emit_vanes(shape, detail, FlatShaft{},
             VanesOut{g.vane_positions.data(), g.vane_uv_barb.data(), g.vane_uv_vane.data(), g.vane_triangles.data(), 0});
  return g;
}

}  // namespace plume::feathers
