#include "partings/geodesic.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace plume::partings {

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct PositionHash {
  size_t operator()(const Eigen::Vector3f &p) const {
    size_t h = 0;
    for (int i = 0; i < 3; ++i) {
      uint32_t bits;
      std::memcpy(&bits, &p[i], 4);
      h = h * 0x9E3779B97F4A7C15ull + bits;
    }
    return h;
  }
};
struct PositionEqual {
  bool operator()(const Eigen::Vector3f &a, const Eigen::Vector3f &b) const { return a == b; }
};

int find_root(std::vector<int> &parent, int i) {
  while (parent[size_t(i)] != i) {
    parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
    i = parent[size_t(i)];
  }
  return i;
}

void unite(std::vector<int> &parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);
}

/// Corner of `triangle` whose welded vertex is `vertex`, or -1.
int corner_of(const Mesh &mesh, const MeshTopology &topology, int triangle, int vertex) {
  for (int c = 0; c < 3; ++c)
    if (topology.welded[size_t(mesh.triangles[size_t(triangle)][c])] == vertex) return c;
  return -1;
}

/// Binary-heap Dijkstra over a CSR graph; `r_distance` holds the seeds on entry.
void dijkstra(std::span<const int64_t> offsets, std::span<const int> targets, std::span<const float> lengths,
              std::vector<float> &r_distance, std::vector<std::pair<float, int>> &heap) {
  heap.clear();
  for (size_t n = 0; n < r_distance.size(); ++n)
    if (r_distance[n] < kInfinity) heap.emplace_back(r_distance[n], int(n));
  const auto later = std::greater<std::pair<float, int>>();
  std::make_heap(heap.begin(), heap.end(), later);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const auto [d, n] = heap.back();
    heap.pop_back();
    if (d > r_distance[size_t(n)]) continue;
    for (int64_t l = offsets[size_t(n)]; l < offsets[size_t(n) + 1]; ++l) {
      const float candidate = d + lengths[size_t(l)];
      const int m = targets[size_t(l)];
      if (candidate < r_distance[size_t(m)]) {
        r_distance[size_t(m)] = candidate;
        heap.emplace_back(candidate, m);
        std::push_heap(heap.begin(), heap.end(), later);
      }
    }
  }
}

}  // namespace

MeshTopology build_topology(const Mesh &mesh) {
  MeshTopology topology;
  topology.welded.resize(mesh.vertex_count());
  std::unordered_map<Eigen::Vector3f, int, PositionHash, PositionEqual> first_at;
  first_at.reserve(mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    topology.welded[v] = first_at.try_emplace(mesh.positions[v], int(v)).first->second;

  // Every triangle edge keyed by its welded end points; an edge met exactly twice links its two
  // triangles, an edge met once or more than twice is a border.
  const size_t edge_count = mesh.triangle_count() * 3;
  std::vector<std::pair<uint64_t, int>> edges(edge_count);  // (key, triangle * 3 + edge)
  for (size_t t = 0; t < mesh.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = topology.welded[size_t(mesh.triangles[t][e])];
      const int b = topology.welded[size_t(mesh.triangles[t][(e + 1) % 3])];
      edges[t * 3 + size_t(e)] = {edge_key(a, b), int(t * 3 + size_t(e))};
    }
  std::sort(edges.begin(), edges.end());
  topology.neighbours.assign(mesh.triangle_count(), Eigen::Vector3i(-1, -1, -1));
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    const uint64_t key = edges[i].first;
    if (j - i == 2 && uint32_t(key >> 32) != uint32_t(key)) {
      const int ta = edges[i].second / 3, ea = edges[i].second % 3;
      const int tb = edges[i + 1].second / 3, eb = edges[i + 1].second % 3;
      if (ta != tb) {
        topology.neighbours[size_t(ta)][ea] = tb;
        topology.neighbours[size_t(tb)][eb] = ta;
      }
    }
    i = j;
  }
  return topology;
}

EdgeCut cut_from_edges(const Mesh &mesh, const MeshTopology &topology, std::span<const uint64_t> edge_keys) {
  EdgeCut cut(mesh.triangle_count(), {false, false, false});
  for (size_t t = 0; t < mesh.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) {
      const uint64_t key = edge_key(topology.welded[size_t(mesh.triangles[t][e])],
                                    topology.welded[size_t(mesh.triangles[t][(e + 1) % 3])]);
      cut[t][size_t(e)] = std::binary_search(edge_keys.begin(), edge_keys.end(), key);
    }
  return cut;
}

GeodesicGraph::GeodesicGraph(const Mesh &mesh, const MeshTopology &topology, const EdgeCut &cut) {
  const size_t triangle_count = mesh.triangle_count();
  const auto is_cut = [&](size_t t, int e) { return !cut.empty() && cut[t][size_t(e)]; };

  // Corners of the same welded vertex are one node when a chain of uncut shared edges joins them.
  // Corner c of triangle t touches edges c (to c+1) and c+2 (from c+2).
  std::vector<int> parent(triangle_count * 3);
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t t = 0; t < triangle_count; ++t)
    for (int e = 0; e < 3; ++e) {
      const int n = topology.neighbours[t][e];
      if (n < 0 || is_cut(t, e)) continue;
      for (int end = 0; end < 2; ++end) {
        const int c = (e + end) % 3;
        const int vertex = topology.welded[size_t(mesh.triangles[t][c])];
        const int other = corner_of(mesh, topology, n, vertex);
        if (other >= 0) unite(parent, int(t * 3) + c, n * 3 + other);
      }
    }
  corner_nodes_.resize(triangle_count * 3);
  std::vector<int> node_of_root(triangle_count * 3, -1);
  int node_count = 0;
  for (size_t c = 0; c < triangle_count * 3; ++c) {
    const int root = find_root(parent, int(c));
    if (node_of_root[size_t(root)] < 0) node_of_root[size_t(root)] = node_count++;
    corner_nodes_[c] = node_of_root[size_t(root)];
  }

  struct Link {
    int from, to;
    float length;
  };
  std::vector<Link> links;
  links.reserve(triangle_count * 6);
  for (size_t t = 0; t < triangle_count; ++t) {
    const Eigen::Vector3i &tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const int a = node(int(t), e), b = node(int(t), (e + 1) % 3);
      const float length = (mesh.positions[size_t(tri[(e + 1) % 3])] - mesh.positions[size_t(tri[e])]).norm();
      if (a != b) links.push_back({std::min(a, b), std::max(a, b), length});

      // Unfold the two triangles of an uncut edge into a plane: with the edge p0-p1 on the x axis,
      // the opposite corners sit on either side of it; their straight link is a surface path only
      // when it crosses the shared edge between its end points (a convex quad).
      const int n = topology.neighbours[t][e];
      if (n < 0 || n < int(t) || is_cut(t, e)) continue;
      const Eigen::Vector3f p0 = mesh.positions[size_t(tri[e])];
      const Eigen::Vector3f p1 = mesh.positions[size_t(tri[(e + 1) % 3])];
      const Eigen::Vector3f pc = mesh.positions[size_t(tri[(e + 2) % 3])];
      int far_corner = -1;
      for (int c = 0; c < 3; ++c) {
        const int v = topology.welded[size_t(mesh.triangles[size_t(n)][c])];
        if (v != topology.welded[size_t(tri[e])] && v != topology.welded[size_t(tri[(e + 1) % 3])]) far_corner = c;
      }
      if (far_corner < 0) continue;
      const Eigen::Vector3f pd = mesh.positions[size_t(mesh.triangles[size_t(n)][far_corner])];
      const float edge_length = (p1 - p0).norm();
      if (edge_length <= 0.0f) continue;
      const Eigen::Vector3f axis = (p1 - p0) / edge_length;
      const float xc = (pc - p0).dot(axis), yc = ((pc - p0) - xc * axis).norm();
      const float xd = (pd - p0).dot(axis), yd = ((pd - p0) - xd * axis).norm();
      if (yc + yd <= 0.0f) continue;
      const float x_cross = xc + (xd - xc) * yc / (yc + yd);
      if (x_cross <= 0.0f || x_cross >= edge_length) continue;
      const int from = node(int(t), (e + 2) % 3), to = node(n, far_corner);
      if (from != to) links.push_back({std::min(from, to), std::max(from, to), std::hypot(xc - xd, yc + yd)});
    }
  }
  // Keep the shortest of duplicate links (an edge is met from both of its triangles).
  std::sort(links.begin(), links.end(), [](const Link &l, const Link &r) {
    return std::tie(l.from, l.to, l.length) < std::tie(r.from, r.to, r.length);
  });
  links.erase(std::unique(links.begin(), links.end(),
                          [](const Link &l, const Link &r) { return l.from == r.from && l.to == r.to; }),
              links.end());

  node_offsets_.assign(size_t(node_count) + 1, 0);
  for (const Link &l : links) {
    ++node_offsets_[size_t(l.from) + 1];
    ++node_offsets_[size_t(l.to) + 1];
  }
  for (size_t n = 0; n < size_t(node_count); ++n) node_offsets_[n + 1] += node_offsets_[n];
  link_targets_.resize(links.size() * 2);
  link_lengths_.resize(links.size() * 2);
  std::vector<int64_t> fill(node_offsets_.begin(), node_offsets_.end() - 1);
  for (const Link &l : links) {
    link_targets_[size_t(fill[size_t(l.from)])] = l.to;
    link_lengths_[size_t(fill[size_t(l.from)]++)] = l.length;
    link_targets_[size_t(fill[size_t(l.to)])] = l.from;
    link_lengths_[size_t(fill[size_t(l.to)]++)] = l.length;
  }
}

void GeodesicGraph::distances_from(const Mesh &mesh, const SurfacePoint &source, std::vector<float> &r_distance,
                                   Scratch &scratch) const {
  r_distance.assign(node_count(), kInfinity);
  const Eigen::Vector3f origin = surface_position(mesh, source);
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector3f corner = mesh.positions[size_t(mesh.triangles[size_t(source.triangle)][c])];
    float &d = r_distance[size_t(node(source.triangle, c))];
    d = std::min(d, (corner - origin).norm());
  }
  dijkstra(node_offsets_, link_targets_, link_lengths_, r_distance, scratch.heap);
}

float GeodesicGraph::evaluate(const Mesh &mesh, std::span<const float> distance, const SurfacePoint &p,
                              const SurfacePoint &source) const {
  if (p.triangle == source.triangle) return (surface_position(mesh, p) - surface_position(mesh, source)).norm();
  float d = 0.0f;
  for (int c = 0; c < 3; ++c) {
    const float dc = distance[size_t(node(p.triangle, c))];
    if (dc == kInfinity) return kInfinity;
    d += p.bary[c] * dc;
  }
  return d;
}

std::vector<uint64_t> polyline_edge_path(const Mesh &mesh, const MeshTopology &topology,
                                         std::span<const SurfacePoint> snapped, bool closed) {
  // Vertex graph over welded vertices and mesh edges.
  const size_t vertex_count = mesh.vertex_count();
  std::vector<std::vector<std::pair<int, float>>> adjacent(vertex_count);
  for (const Eigen::Vector3i &tri : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = topology.welded[size_t(tri[e])], b = topology.welded[size_t(tri[(e + 1) % 3])];
      if (a == b) continue;
      const float length = (mesh.positions[size_t(a)] - mesh.positions[size_t(b)]).norm();
      adjacent[size_t(a)].emplace_back(b, length);
      adjacent[size_t(b)].emplace_back(a, length);
    }

  double edge_length_sum = 0.0;
  size_t edge_count = 0;
  for (const auto &links : adjacent)
    for (const auto &link : links) edge_length_sum += link.second, ++edge_count;
  const float mean_edge = edge_count ? float(edge_length_sum / double(edge_count)) : 0.0f;

  std::vector<int> vertices;
  for (const SurfacePoint &sp : snapped) {
    int corner = 0;
    sp.bary.maxCoeff(&corner);
    const int v = topology.welded[size_t(mesh.triangles[size_t(sp.triangle)][corner])];
    if (vertices.empty() || vertices.back() != v) vertices.push_back(v);
  }
  if (closed && vertices.size() > 2 && vertices.front() != vertices.back()) vertices.push_back(vertices.front());

  std::vector<uint64_t> keys;
  std::vector<float> distance(vertex_count);
  std::vector<int> previous(vertex_count);
  std::vector<std::pair<float, int>> heap;
  const auto later = std::greater<std::pair<float, int>>();
  for (size_t i = 0; i + 1 < vertices.size(); ++i) {
    const int from = vertices[i], to = vertices[i + 1];
    const Eigen::Vector3f centre = 0.5f * (mesh.positions[size_t(from)] + mesh.positions[size_t(to)]);
    const float chord = (mesh.positions[size_t(to)] - mesh.positions[size_t(from)]).norm();
    // First within a ball around the two points, so a path never goes the other way round the
    // head; then anywhere, for a line drawn across a fold.
    for (const float radius : {0.75f * chord + mean_edge, std::numeric_limits<float>::infinity()}) {
      std::fill(distance.begin(), distance.end(), kInfinity);
      std::fill(previous.begin(), previous.end(), -1);
      distance[size_t(from)] = 0.0f;
      heap.assign(1, {0.0f, from});
      while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), later);
        const auto [d, v] = heap.back();
        heap.pop_back();
        if (v == to) break;
        if (d > distance[size_t(v)]) continue;
        for (const auto &[w, length] : adjacent[size_t(v)]) {
          if ((mesh.positions[size_t(w)] - centre).norm() > radius) continue;
          if (d + length < distance[size_t(w)]) {
            distance[size_t(w)] = d + length;
            previous[size_t(w)] = v;
            heap.emplace_back(d + length, w);
            std::push_heap(heap.begin(), heap.end(), later);
          }
        }
      }
      if (distance[size_t(to)] < kInfinity) break;
    }
    for (int v = to; previous[size_t(v)] >= 0; v = previous[size_t(v)]) keys.push_back(edge_key(v, previous[size_t(v)]));
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

}  // namespace plume::partings
