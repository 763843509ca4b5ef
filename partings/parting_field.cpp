#include "partings/parting_field.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "groom/error.h"
#include "groom/mesh_query.h"
#include "partings/geodesic.h"

namespace plume::partings {

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

std::string describe_point(const Eigen::Vector3f &p) {
  std::ostringstream out;
  out.precision(4);
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

/// Reads a zone map: one integer zone id per triangle, one per line; blank lines and lines
/// starting with '#' are skipped.
std::vector<long long> read_zone_map(const std::string &path, size_t triangle_count, const FileLoc &setting) {
  std::ifstream in(path);
  if (!in) throw InputError(setting, "partings.zone_map: cannot open zone map file '" + path + "'");
  std::vector<long long> ids;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    long long id = 0;
    std::string rest;
    if (!(fields >> id) || (fields >> rest)) {
      FileLoc loc{path, line_number, int(first) + 1};
      throw InputError(loc, "expected one integer zone id for triangle " + std::to_string(ids.size()) + ", got \"" +
                                line.substr(first) + "\"");
    }
    ids.push_back(id);
  }
  if (ids.size() != triangle_count)
    throw InputError(FileLoc{path, line_number, 0}, "zone map has " + std::to_string(ids.size()) +
                                                        " zone ids, the mesh has " + std::to_string(triangle_count) +
                                                        " triangles");
  return ids;
}

}  // namespace

struct PartingField::Impl {
  Mesh mesh;  // positions and triangles of the rest mesh, for evaluating distances
  std::vector<int> triangle_zone;  // #F, empty when there are no zones
  std::vector<std::string> zone_names;
  std::vector<int> guide_zones;  // one per guide
  std::vector<SurfacePoint> guide_roots;
  /// Where the groom's partings are written and the zone map file, if any (for messages).
  FileLoc loc;
  std::string zones_key;  // the groom key the zones come from
  std::string zone_map_path;

  struct Partial {
    float gamma = 1.0f;
    GeodesicGraph graph;
    /// Intact-graph nodes of the vertices on the cut.
    std::vector<int> cut_nodes;
    /// Longest link that can start next to the cut and jump over it (twice the longest edge of
    /// the triangles touching it).
    float jump = 0.0f;
    /// #guides: a lower bound on the intact distance from the guide to any path crossing the line.
    std::vector<float> reach;
    /// #guides by graph.node_count(), distances on the cut mesh, each filled on first use.
    mutable std::vector<float> fields;
    std::unique_ptr<std::once_flag[]> ready;
  };
  std::unique_ptr<GeodesicGraph> intact;
  std::vector<float> intact_fields;  // #guides by intact->node_count()
  std::vector<Partial> partials;

  void build_zones(const MeshTopology &topology, const MeshQuery &query, const PartingSettings &settings);
  std::span<const float> intact_field(size_t guide) const {
    return {intact_fields.data() + guide * intact->node_count(), intact->node_count()};
  }
  /// The cut-mesh distance field of a guide, computed on first use (thread-safe; the result does
  /// not depend on which thread computes it).
  std::span<const float> cut_field(size_t line, size_t guide) const {
    const Partial &p = partials[line];
    float *field = p.fields.data() + guide * p.graph.node_count();
    std::call_once(p.ready[guide], [&] {
      GeodesicGraph::Scratch scratch;
      std::vector<float> distance;
      p.graph.distances_from(mesh, guide_roots[guide], distance, scratch);
      std::copy(distance.begin(), distance.end(), field);
    });
    return {field, p.graph.node_count()};
  }
};

void PartingField::Impl::build_zones(const MeshTopology &topology, const MeshQuery &query,
                                     const PartingSettings &settings) {
  const size_t triangle_count = mesh.triangle_count();
  std::vector<int> base(triangle_count, 0);
  std::vector<std::string> base_names{"surface"};
  using Source = PartingSettings::ZoneSource;

  if (settings.zone_source == Source::face_groups) {
    base_names.clear();
    std::vector<int> zone_of_group(mesh.group_names.size(), -1);
    if (settings.zone_groups.empty()) {
      for (size_t g = 0; g < mesh.group_names.size(); ++g) {
        zone_of_group[g] = int(base_names.size());
        base_names.push_back("face group '" + mesh.group_names[g] + "'");
      }
    } else {
      for (const std::string &name : settings.zone_groups) {
        const int g = mesh.group_index(name);
        if (g < 0)
          throw InputError(settings.zone_groups_loc.file.empty() ? settings.loc : settings.zone_groups_loc,
                           "partings.zones.groups: the mesh has no face group '" + name + "' (groups: " +
                               mesh.group_list() + ")");
        zone_of_group[size_t(g)] = int(base_names.size());
        base_names.push_back("face group '" + name + "'");
      }
      const int others = int(base_names.size());
      bool any_other = false;
      for (int &z : zone_of_group)
        if (z < 0) z = others, any_other = true;
      if (any_other) base_names.push_back("the faces outside the listed zone groups");
    }
    for (size_t t = 0; t < triangle_count; ++t) base[t] = zone_of_group[size_t(mesh.triangle_groups[t])];
  } else if (settings.zone_source == Source::zone_map) {
    const std::vector<long long> ids = read_zone_map(settings.zone_map_path, triangle_count, settings.loc);
    std::map<long long, int> dense;
    for (long long id : ids) dense.emplace(id, 0);
    base_names.clear();
    for (auto &[id, z] : dense) {
      z = int(base_names.size());
      base_names.push_back("zone map id " + std::to_string(id));
    }
    for (size_t t = 0; t < triangle_count; ++t) base[t] = dense[ids[t]];
  }

  // Hard lines cut the surface: zones are the regions of each base zone that triangle adjacency
  // joins without crossing a cut edge.
  std::vector<std::vector<uint64_t>> hard_edges;
  std::vector<uint64_t> all_hard;
  for (const PartingLine &line : settings.lines) {
    if (!line.hard) continue;
    std::vector<SurfacePoint> snapped;
    for (const Eigen::Vector3f &p : line.points) snapped.push_back(query.closest(p));
    hard_edges.push_back(polyline_edge_path(mesh, topology, snapped, line.closed));
    all_hard.insert(all_hard.end(), hard_edges.back().begin(), hard_edges.back().end());
  }
  if (settings.zone_source == Source::lines && hard_edges.empty())
    throw InputError(settings.loc, "partings: zones come from parting lines, but no parting line is hard");
  if (settings.zone_source == Source::none && hard_edges.empty()) return;

  std::sort(all_hard.begin(), all_hard.end());
  const EdgeCut cut = cut_from_edges(mesh, topology, all_hard);
  triangle_zone.assign(triangle_count, -1);
  std::vector<std::vector<int>> regions_of_base(base_names.size());
  std::vector<int> stack;
  int zone_count = 0;
  for (size_t seed = 0; seed < triangle_count; ++seed) {
    if (triangle_zone[seed] >= 0) continue;
    const int zone = zone_count++;
    regions_of_base[size_t(base[seed])].push_back(zone);
    triangle_zone[seed] = zone;
    stack.assign(1, int(seed));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        const int n = topology.neighbours[size_t(t)][e];
        if (n < 0 || cut[size_t(t)][size_t(e)] || triangle_zone[size_t(n)] >= 0 || base[size_t(n)] != base[size_t(t)])
          continue;
        triangle_zone[size_t(n)] = zone;
        stack.push_back(n);
      }
    }
  }

  // A face group in two pieces stays one zone; only hard lines split zones into regions.
  if (hard_edges.empty()) {
    for (size_t t = 0; t < triangle_count; ++t) triangle_zone[t] = base[t];
    zone_names = base_names;
    return;
  }

  std::vector<Eigen::Vector3d> centroid_sum(size_t(zone_count), Eigen::Vector3d::Zero());
  std::vector<double> area_sum(size_t(zone_count), 0.0);
  for (size_t t = 0; t < triangle_count; ++t) {
    const double area = mesh.triangle_area(t);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) centre += mesh.positions[size_t(mesh.triangles[t][c])].cast<double>() / 3.0;
    centroid_sum[size_t(triangle_zone[t])] += area * centre;
    area_sum[size_t(triangle_zone[t])] += area;
  }
  zone_names.assign(size_t(zone_count), "");
  for (size_t b = 0; b < base_names.size(); ++b)
    for (const int zone : regions_of_base[b]) {
      const Eigen::Vector3d centre =
          area_sum[size_t(zone)] > 0.0 ? Eigen::Vector3d(centroid_sum[size_t(zone)] / area_sum[size_t(zone)])
                                       : Eigen::Vector3d::Zero();
      zone_names[size_t(zone)] = regions_of_base[b].size() == 1
                                     ? base_names[b]
                                     : "the region of " + base_names[b] + " cut by hard partings around " +
                                           describe_point(centre.cast<float>());
    }

  // A hard line that separates nothing is a mistake worth naming (it is neither closed nor reaches
  // the border of the mesh).
  size_t hard_index = 0;
  for (const PartingLine &line : settings.lines) {
    if (!line.hard) continue;
    const std::vector<uint64_t> &edges = hard_edges[hard_index++];
    bool separates = false;
    for (size_t t = 0; t < triangle_count && !separates; ++t)
      for (int e = 0; e < 3; ++e) {
        const int n = topology.neighbours[t][e];
        if (n < 0 || triangle_zone[size_t(n)] == triangle_zone[t]) continue;
        const uint64_t key = edge_key(topology.welded[size_t(mesh.triangles[t][e])],
                                      topology.welded[size_t(mesh.triangles[t][(e + 1) % 3])]);
        if (std::binary_search(edges.begin(), edges.end(), key)) separates = true;
      }
    if (!separates)
      throw InputError(line.loc, "hard parting line '" + line.name +
                                     "' does not cut the surface into separate regions: close it, or extend it "
                                     "to the border of the mesh, or make it a partial parting (hard: false)");
  }
}

PartingField::PartingField(const Mesh &rest_mesh, const Guides &guides, const PartingSettings &settings)
    : impl_(std::make_unique<Impl>()) {
  Impl &im = *impl_;
  im.mesh.positions = rest_mesh.positions;
  im.mesh.triangles = rest_mesh.triangles;
  im.mesh.triangle_groups = rest_mesh.triangle_groups;
  im.mesh.group_names = rest_mesh.group_names;
  im.mesh.vertex_normals = rest_mesh.vertex_normals;
  if (im.mesh.vertex_normals.size() != im.mesh.positions.size()) im.mesh.compute_normals();
  im.guide_roots = guides.roots;

  for (const PartingLine &line : settings.lines) {
    if (line.points.size() < 2)
      throw InputError(line.loc, "parting line '" + line.name + "': needs at least 2 points, got " +
                                     std::to_string(line.points.size()));
    if (!(line.gamma >= 1.0f) || !std::isfinite(line.gamma))
      throw InputError(line.loc, "parting line '" + line.name + "': gamma must be >= 1, got " +
                                     std::to_string(line.gamma));
  }

  const MeshTopology topology = build_topology(im.mesh);
  const MeshQuery query(im.mesh);
  im.build_zones(topology, query, settings);
  im.loc = settings.loc;
  im.zones_key = settings.zone_source == PartingSettings::ZoneSource::none ? "partings.lines" : "partings.zones";
  if (settings.zone_source == PartingSettings::ZoneSource::zone_map) im.zone_map_path = settings.zone_map_path;
  if (im.zone_names.empty()) im.zone_names.push_back("surface");
  im.guide_zones.resize(guides.size());
  for (size_t g = 0; g < guides.size(); ++g) im.guide_zones[g] = zone_of(guides.roots[g]);

  // Partial lines: one distance field per guide on the intact mesh, shared by every line, and one
  // per guide and line on the mesh cut open along that line. The cut fields are computed on first
  // use: a root whose intact distances from a guide all stay below the guide's reach to the line
  // has D1 = D, so guides far from a line (most of them) never need one.
  const size_t guide_count = guides.size();
  im.intact = std::make_unique<GeodesicGraph>(im.mesh, topology);
  for (const PartingLine &line : settings.lines) {
    if (line.hard) continue;
    std::vector<SurfacePoint> snapped;
    for (const Eigen::Vector3f &p : line.points) snapped.push_back(query.closest(p));
    const std::vector<uint64_t> edges = polyline_edge_path(im.mesh, topology, snapped, line.closed);
    Impl::Partial partial{line.gamma, GeodesicGraph(im.mesh, topology, cut_from_edges(im.mesh, topology, edges)),
                          {}, 0.0f, {}, {}, {}};
    std::vector<bool> on_cut(im.mesh.vertex_count(), false);
    for (const uint64_t key : edges) on_cut[size_t(key >> 32)] = on_cut[size_t(uint32_t(key))] = true;
    for (size_t t = 0; t < im.mesh.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) {
        if (!on_cut[size_t(topology.welded[size_t(im.mesh.triangles[t][c])])]) continue;
        partial.cut_nodes.push_back(im.intact->node(int(t), c));
        for (int e = 0; e < 3; ++e)
          partial.jump = std::max(partial.jump, 2.0f * (im.mesh.positions[size_t(im.mesh.triangles[t][(e + 1) % 3])] -
                                                        im.mesh.positions[size_t(im.mesh.triangles[t][e])])
                                                           .norm());
      }
    std::sort(partial.cut_nodes.begin(), partial.cut_nodes.end());
    partial.cut_nodes.erase(std::unique(partial.cut_nodes.begin(), partial.cut_nodes.end()), partial.cut_nodes.end());
    partial.reach.assign(guide_count, kInfinity);
    partial.fields.resize(guide_count * partial.graph.node_count());
    partial.ready = std::make_unique<std::once_flag[]>(guide_count);
    im.partials.push_back(std::move(partial));
  }
  if (im.partials.empty()) {
    im.intact.reset();
    return;
  }

  im.intact_fields.resize(guide_count * im.intact->node_count());
#pragma omp parallel
  {
    GeodesicGraph::Scratch scratch;
    std::vector<float> field;
#pragma omp for schedule(dynamic, 4)
    for (int64_t g = 0; g < int64_t(guide_count); ++g) {
      im.intact->distances_from(im.mesh, guides.roots[size_t(g)], field, scratch);
      std::copy(field.begin(), field.end(), im.intact_fields.begin() + g * int64_t(im.intact->node_count()));
      // A path that crosses the line either passes a cut vertex v (length >= d(v)) or jumps over a
      // cut edge on a link of length <= jump starting at a node c next to v (d(c) >= d(v) - jump).
      for (Impl::Partial &p : im.partials) {
        float nearest = kInfinity;
        for (const int n : p.cut_nodes) nearest = std::min(nearest, field[size_t(n)]);
        p.reach[size_t(g)] = nearest - p.jump;
      }
    }
  }
}

PartingField::~PartingField() = default;
PartingField::PartingField(PartingField &&) noexcept = default;
PartingField &PartingField::operator=(PartingField &&) noexcept = default;

bool PartingField::empty() const { return impl_->triangle_zone.empty() && impl_->partials.empty(); }

int PartingField::zone_count() const { return int(impl_->zone_names.size()); }

int PartingField::zone_of(const SurfacePoint &p) const {
  if (impl_->triangle_zone.empty()) return 0;
  return impl_->triangle_zone[size_t(p.triangle)];
}

int PartingField::guide_zone(size_t guide) const { return impl_->guide_zones[guide]; }

const std::string &PartingField::zone_name(int zone) const { return impl_->zone_names[size_t(zone)]; }

void PartingField::check_roots_have_guides(std::span<const SurfacePoint> roots) const {
  if (impl_->triangle_zone.empty()) {
    if (!roots.empty() && impl_->guide_zones.empty())
      throw InputError("there are roots to grow but no guide to grow them from");
    return;
  }
  std::vector<bool> has_guide(size_t(zone_count()), false);
  for (const int z : impl_->guide_zones) has_guide[size_t(z)] = true;
  for (const SurfacePoint &root : roots) {
    const int z = zone_of(root);
    if (!has_guide[size_t(z)]) {
      const std::string message =
          impl_->zones_key + ": hard parting zone " + zone_name(z) +
          (impl_->zone_map_path.empty() ? "" : " (of " + impl_->zone_map_path + ")") +
          " has roots but no guide: add a guide whose root is in it, or keep roots out of it";
      throw InputError(impl_->loc, message);
    }
  }
}

float PartingField::geodesic_distance(const SurfacePoint &root, size_t guide) const {
  if (!impl_->intact) throw InternalError("PartingField::geodesic_distance: there is no partial parting");
  return impl_->intact->evaluate(impl_->mesh, impl_->intact_field(guide), root, impl_->guide_roots[guide]);
}

float PartingField::detour_distance(const SurfacePoint &root, size_t guide, size_t line) const {
  const Impl::Partial &p = impl_->partials.at(line);
  return p.graph.evaluate(impl_->mesh, impl_->cut_field(line, guide), root, impl_->guide_roots[guide]);
}

size_t PartingField::partial_line_count() const { return impl_->partials.size(); }

float PartingField::weight_factor(const SurfacePoint &root, size_t guide) const {
  const Impl &im = *impl_;
  if (!im.triangle_zone.empty() && zone_of(root) != im.guide_zones[guide]) return 0.0f;
  if (im.partials.empty()) return 1.0f;
  const float d = geodesic_distance(root, guide);
  // Not connected on the surface at all (separate mesh pieces): partings have nothing to say.
  if (d == kInfinity || d <= 0.0f) return 1.0f;
  const std::span<const float> intact = im.intact_field(guide);
  float farthest_corner = 0.0f;
  for (int c = 0; c < 3; ++c)
    farthest_corner = std::max(farthest_corner, intact[size_t(im.intact->node(root.triangle, c))]);
  float factor = 1.0f;
  for (size_t l = 0; l < im.partials.size(); ++l) {
    // Shortest paths to the root's corners that stop short of the line exist on the cut mesh too.
    if (farthest_corner < im.partials[l].reach[guide] || root.triangle == im.guide_roots[guide].triangle) continue;
    const float d1 = detour_distance(root, guide, l);
    if (d1 == kInfinity) return 0.0f;
    // Every path on the cut mesh is a path on the intact mesh, so d1 >= d node by node and
    // hence after barycentric blending; the clamp only guards rounding.
    const float ratio = std::min(1.0f, d / d1);
    factor *= std::pow(ratio, im.partials[l].gamma);
  }
  return factor;
}

}  // namespace plume::partings
