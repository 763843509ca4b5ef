#include "feathers/layering.h"

#include <Eigen/Geometry>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <nanoflann.hpp>
#include <optional>
#include <queue>
#include <set>
#include <string>
#include <tuple>

#include "feathers/coat.h"
#include "groom/error.h"
#include "groom/segment_distance.h"
#include "skin/skin_grid.h"

namespace plume::feathers {

namespace {

using Vec = Eigen::Vector3d;
using Triangle = std::array<Vec, 3>;

/// Triangles of a feather are kept apart in groups of this many consecutive ones (a vane row or so),
/// each with a bounding sphere: the first level of the test.
constexpr int kGroup = 8;

/// A feather whose turn of the frame before no longer clears looks for the nearest turn that does
/// this many steps of the search either way (0.06 radians) before the search over the whole range:
/// looking farther made more turns jump on the bird (a turn kept high crowds the feathers above).
constexpr int kLocalSteps = 3;

/// A shrunk feather whose size of the frame before no longer clears looks for the nearest size that
/// does by this many steps down (each the warm start's fall-back step) before a bisection from there.
constexpr int kShrinkSteps = 16;

/// Turning aside (docs/feathers.md, "Turned aside"): the yaws about the skin normal tried, nearest
/// first, and the steps of the turn tried at each (then bisection to kAsideTolerance radians).
constexpr double kAsideYaws[] = {0.1, -0.1, 0.2, -0.2, 0.3, -0.3, 0.45, -0.45};
constexpr double kAsideStep = 0.05;
constexpr double kAsideTolerance = 1e-3;

/// Bending (docs/feathers.md, "Bent"): the bends tried, as (where the bend starts, a fraction of the
/// shaft's length; the bend at the tip, radians, positive toward the skin normal), the smallest change
/// of shape, (1 - start) |bend|, first (down first): at most 0.4, so the tip moves by at most about a
/// fifth of the feather's length.
constexpr std::pair<double, double> kBends[] = {
    {0.2, -0.1}, {0.6, -0.2}, {0.2, 0.1},  {0.6, 0.2},  {0.4, -0.15}, {0.4, 0.15}, {0.2, -0.2},
    {0.6, -0.4}, {0.2, 0.2},  {0.6, 0.4},  {0.4, -0.3}, {0.4, 0.3},   {0.2, -0.3}, {0.6, -0.6},
    {0.2, 0.3},  {0.6, 0.6},  {0.4, -0.45}, {0.4, 0.45}, {0.2, -0.4}, {0.6, -0.8}, {0.2, 0.4},
    {0.6, 0.8},  {0.4, -0.6}, {0.4, 0.6},  {0.2, -0.5}, {0.6, -1.0},  {0.2, 0.5},  {0.6, 1.0}};

/// The checker's root disc (check/vanes.h, OverlapOptions): vertices within this fraction of their
/// feather's extent from its vane base cast no ray when the order reads which feather lies over which.
constexpr double kCheckerRootDisc = 0.05;

// Closest distances (Ericson, "Real-Time Collision Detection", 5.1.5; segments: groom/segment_distance.h), squared.
double point_triangle_squared(const Vec &p, const Triangle &t) {
  const Vec &a = t[0], &b = t[1], &c = t[2];
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.squaredNorm();
  const Vec bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (p - (a + d1 / (d1 - d3) * ab)).squaredNorm();
  const Vec cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (p - (a + d2 / (d2 - d6) * ac)).squaredNorm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).squaredNorm();
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) return std::min({ap.squaredNorm(), bp.squaredNorm(), cp.squaredNorm()});
  const double v = vb / sum, w = vc / sum;
  return (p - (a + ab * v + ac * w)).squaredNorm();
}

/// Whether segment pq crosses triangle t (its plane between p and q, the crossing inside t; signed
/// volumes, so a segment in the triangle's plane never crosses: the distances catch it).
bool segment_crosses(const Vec &p, const Vec &q, const Triangle &t) {
  const Vec n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double dp = n.dot(p - t[0]), dq = n.dot(q - t[0]);
  if ((dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq) return false;
  const Vec x = p + (dp / (dp - dq)) * (q - p);
  const double s0 = n.dot((t[1] - t[0]).cross(x - t[0])), s1 = n.dot((t[2] - t[1]).cross(x - t[1])),
               s2 = n.dot((t[0] - t[2]).cross(x - t[2]));
  return (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
}

/// Whether every vertex of `a` lies farther than sqrt(gap2) from b's plane, on one side: then all of
/// `a` does (a convex combination), and so it is that far from `b`. A slack of 1e-9 of the
/// triangles' size keeps rounding on the side of testing further.
bool beyond_plane(const Triangle &a, const Triangle &b, double gap2) {
  const Vec n = (b[1] - b[0]).cross(b[2] - b[0]);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0.0)) return false;
  const double d0 = n.dot(a[0] - b[0]), d1 = n.dot(a[1] - b[0]), d2 = n.dot(a[2] - b[0]);
  const double size = (a[0] - b[0]).norm() + (a[1] - a[0]).norm() + (a[2] - a[0]).norm() + (b[1] - b[0]).norm() +
                      (b[2] - b[0]).norm();
  const double reach = std::sqrt(gap2 * n2) + 1e-9 * size * std::sqrt(n2);
  return (d0 > reach && d1 > reach && d2 > reach) || (d0 < -reach && d1 < -reach && d2 < -reach);
}

/// Whether two triangles intersect or come within sqrt(gap2) of each other. Two triangles that do
/// not intersect are nearest at a vertex of one against the other or at two edges.
bool too_close(const Triangle &a, const Triangle &b, double gap2) {
  if (beyond_plane(a, b, gap2) || beyond_plane(b, a, gap2)) return false;
  for (int k = 0; k < 3; ++k) {
    if (segment_crosses(a[size_t(k)], a[size_t((k + 1) % 3)], b)) return true;
    if (segment_crosses(b[size_t(k)], b[size_t((k + 1) % 3)], a)) return true;
  }
  for (int k = 0; k < 3; ++k) {
    if (point_triangle_squared(a[size_t(k)], b) < gap2) return true;
    if (point_triangle_squared(b[size_t(k)], a) < gap2) return true;
    for (int m = 0; m < 3; ++m)
      if (segment_distance_squared(a[size_t(k)], a[size_t((k + 1) % 3)], b[size_t(m)], b[size_t((m + 1) % 3)]) < gap2)
        return true;
  }
  return false;
}

/// A feather's vanes this frame, in double: its triangles outside the root disc, grouped.
struct FeatherVanes {
  Vec root = Vec::Zero();
  double extent = 0.0;  // from the root
  std::vector<Triangle> triangles;
  std::vector<Eigen::AlignedBox3d> boxes;  // per triangle
  std::vector<Vec> centers;  // per group
  std::vector<double> radii;
  std::vector<Eigen::AlignedBox3d> group_boxes;  // per group
  Eigen::AlignedBox3d box;  // all the triangles
};

FeatherVanes feather_vanes(const CoatFrame &frame, const FeatherRanges &ranges, size_t i, float root_disc) {
  FeatherVanes f;
  f.root = frame.root_frames[i].origin.cast<double>();
  const VaneMesh &v = frame.vanes;
  const int64_t t0 = ranges.first_triangle[i], t1 = ranges.first_triangle[i + 1];
  if (t0 == t1) return f;
  const Vec base = v.positions[size_t(v.triangles[size_t(t0)][0])].cast<double>();
  double from_base = 0.0;
  for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x) {
    const Vec p = v.positions[size_t(x)].cast<double>();
    from_base = std::max(from_base, (p - base).norm());
    f.extent = std::max(f.extent, (p - f.root).norm());
  }
  const double disc = double(root_disc) * from_base;
  for (int64_t t = t0; t < t1; ++t) {
    Triangle tri;
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      tri[size_t(k)] = v.positions[size_t(v.triangles[size_t(t)][k])].cast<double>();
      inside = inside && (tri[size_t(k)] - base).norm() <= disc;
    }
    if (!inside) {
      f.triangles.push_back(tri);
      Eigen::AlignedBox3d box;
      for (const Vec &p : tri) box.extend(p);
      f.boxes.push_back(box);
    }
  }
  for (size_t g = 0; g < f.triangles.size(); g += kGroup) {
    const size_t end = std::min(f.triangles.size(), g + kGroup);
    Eigen::AlignedBox3d box;
    for (size_t t = g; t < end; ++t)
      for (const Vec &p : f.triangles[t]) box.extend(p);
    const Vec c = box.center();
    double r = 0.0;
    for (size_t t = g; t < end; ++t)
      for (const Vec &p : f.triangles[t]) r = std::max(r, (p - c).norm());
    f.centers.push_back(c);
    f.radii.push_back(r);
    f.group_boxes.push_back(box);
    f.box.extend(box);
  }
  return f;
}

/// Whether segment pq meets `box` grown by a margin that covers rounding (slabs): false only when
/// no point of the segment can lie in the box, so a test it skips would have failed.
bool segment_meets_box(const Vec &p, const Vec &q, const Eigen::AlignedBox3d &box) {
  if (box.isEmpty()) return false;
  const double margin = 1e-9 * ((box.max() - box.min()).norm() + (q - p).norm() + p.cwiseAbs().maxCoeff() +
                                box.max().cwiseAbs().maxCoeff() + box.min().cwiseAbs().maxCoeff());
  const Vec lo = box.min().array() - margin, hi = box.max().array() + margin;
  double t0 = 0.0, t1 = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double d = q[a] - p[a];
    if (std::abs(d) < 1e-300) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    double u = (lo[a] - p[a]) / d, v = (hi[a] - p[a]) / d;
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
    if (t0 > t1) return false;
  }
  return true;
}

/// How far along the unit `direction` from `origin` the ray crosses triangle t, or -1 (Moller and
/// Trumbore, in double; a ray in the triangle's plane does not cross it).
double ray_crossing(const Vec &origin, const Vec &direction, const Triangle &t) {
  const Vec e1 = t[1] - t[0], e2 = t[2] - t[0], h = direction.cross(e2);
  const double det = e1.dot(h);
  if (!(std::abs(det) > 1e-300)) return -1.0;
  const Vec s = origin - t[0];
  const double u = s.dot(h) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Vec q = s.cross(e1);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return e2.dot(q) / det;
}

/// The skin's vertices, for nanoflann: the normals near a feather bound the directions of its ways out.
struct SkinVertices {
  const std::vector<Eigen::Vector3f> *positions = nullptr;
  size_t kdtree_get_point_count() const { return positions->size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return (*positions)[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box &) const {
    return false;
  }
};
using SkinVertexTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, SkinVertices>, SkinVertices, 3>;

/// The feathers' indices sorted by their roots' x (then index), for the sweeps below.
std::vector<int32_t> order_by_x(const std::vector<Vec> &roots) {
  std::vector<int32_t> by_x(roots.size());
  for (size_t i = 0; i < roots.size(); ++i) by_x[i] = int32_t(i);
  std::sort(by_x.begin(), by_x.end(), [&](int32_t a, int32_t b) {
    return roots[size_t(a)].x() < roots[size_t(b)].x() || (roots[size_t(a)].x() == roots[size_t(b)].x() && a < b);
  });
  return by_x;
}

/// A bounding volume hierarchy over every feather's triangle groups, for the rays of the order at
/// rest: a ray meets only the groups whose boxes it passes, found by descending the tree, where
/// testing every feather near its origin made the order's time grow with the square of the feather
/// count (the feathers near a vertex grow with the count, as the coat thickens).
class GroupTree {
 public:
  explicit GroupTree(const std::vector<FeatherVanes> &vanes) {
    Eigen::AlignedBox3d all;
    double largest = 0.0;
    for (size_t i = 0; i < vanes.size(); ++i)
      for (size_t g = 0; g < vanes[i].group_boxes.size(); ++g) {
        all.extend(vanes[i].group_boxes[g]);
        largest = std::max(largest, vanes[i].extent);
      }
    if (all.isEmpty()) return;
    // Boxes are grown by far more than segment_meets_box's margin (1e-9 of the sizes and coordinates)
    // and the slab test's rounding (about 1e-16 of them), so that a group whose box a segment meets
    // by segment_meets_box is never skipped.
    const double pad = 1e-6 * ((all.max() - all.min()).norm() + all.max().cwiseAbs().maxCoeff() +
                               all.min().cwiseAbs().maxCoeff() + largest);
    for (size_t i = 0; i < vanes.size(); ++i)
      for (size_t g = 0; g < vanes[i].group_boxes.size(); ++g) {
        Leaf leaf;
        leaf.box = vanes[i].group_boxes[g];
        leaf.box.min().array() -= pad;
        leaf.box.max().array() += pad;
        leaf.reach = vanes[i].extent;
        leaf.feather = int32_t(i);
        leaf.group = int32_t(g);
        leaves_.push_back(leaf);
      }
    nodes_.resize(1);
    fill(0, 0, leaves_.size());
  }

  /// Calls visit(feather, group) for every group whose box (grown as above) the segment from `origin`
  /// along the unit `direction`, as long as the group's feather's extent, meets: every group whose box
  /// segment_meets_box finds that segment meeting, and a few more.
  template <class Visit>
  void for_each_met(const Vec &origin, const Vec &direction, Visit &&visit) const {
    if (nodes_.empty()) return;
    const Vec inverse = direction.cwiseInverse();
    size_t stack[64];
    size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node &node = nodes_[stack[--top]];
      if (!segment_meets(origin, direction, inverse, node.reach, node.box)) continue;
      if (node.count == 0) {
        stack[top++] = size_t(node.first);
        stack[top++] = size_t(node.first) + 1;
        continue;
      }
      for (size_t l = size_t(node.first); l < size_t(node.first + node.count); ++l) {
        const Leaf &leaf = leaves_[l];
        if (segment_meets(origin, direction, inverse, leaf.reach, leaf.box))
          visit(size_t(leaf.feather), size_t(leaf.group));
      }
    }
  }

 private:
  static constexpr size_t kLeafSize = 4;
  struct Leaf {
    Eigen::AlignedBox3d box;  // the group's, grown
    double reach = 0.0;       // its feather's extent
    int32_t feather = 0, group = 0;
  };
  struct Node {
    Eigen::AlignedBox3d box;  // of its leaves' boxes
    double reach = 0.0;       // the largest of their reaches
    int32_t first = 0;        // with leaves: the first of them; else its children, first and first + 1
    int32_t count = 0;        // its leaves (0: it has children)
  };

  /// Whether the segment from `origin` along the unit `direction` (`inverse` its components'
  /// inverses), `length` long, meets `box` (slabs, parameterised by the distance along it).
  static bool segment_meets(const Vec &origin, const Vec &direction, const Vec &inverse, double length,
                            const Eigen::AlignedBox3d &box) {
    double t0 = 0.0, t1 = length;
    for (int a = 0; a < 3; ++a) {
      if (direction[a] == 0.0) {
        if (origin[a] < box.min()[a] || origin[a] > box.max()[a]) return false;
        continue;
      }
      double u = (box.min()[a] - origin[a]) * inverse[a], v = (box.max()[a] - origin[a]) * inverse[a];
      if (u > v) std::swap(u, v);
      t0 = std::max(t0, u);
      t1 = std::min(t1, v);
      if (t0 > t1) return false;
    }
    return true;
  }

  /// Fills node `index` (already in nodes_) for leaves [begin, end): their box and reach, and either
  /// the leaves themselves or two children appended as a pair, the leaves split at their median
  /// along the longest axis of their centers' box.
  void fill(size_t index, size_t begin, size_t end) {
    Node node;
    Eigen::AlignedBox3d spread;
    for (size_t l = begin; l < end; ++l) {
      node.box.extend(leaves_[l].box);
      node.reach = std::max(node.reach, leaves_[l].reach);
      spread.extend(leaves_[l].box.center());
    }
    if (end - begin <= kLeafSize) {
      node.first = int32_t(begin);
      node.count = int32_t(end - begin);
      nodes_[index] = node;
      return;
    }
    int axis = 0;
    (spread.max() - spread.min()).maxCoeff(&axis);
    const size_t middle = begin + (end - begin) / 2;
    std::nth_element(leaves_.begin() + std::ptrdiff_t(begin), leaves_.begin() + std::ptrdiff_t(middle),
                     leaves_.begin() + std::ptrdiff_t(end), [&](const Leaf &a, const Leaf &b) {
                       const double ca = a.box.center()[axis], cb = b.box.center()[axis];
                       return ca < cb || (ca == cb && std::tie(a.feather, a.group) < std::tie(b.feather, b.group));
                     });
    node.first = int32_t(nodes_.size());
    nodes_[index] = node;
    nodes_.resize(nodes_.size() + 2);
    fill(size_t(node.first), begin, middle);
    fill(size_t(node.first) + 1, middle, end);
  }

  std::vector<Node> nodes_;
  std::vector<Leaf> leaves_;
};

/// Per feather, the lower ones (by `rank`) it may touch or lie under at any lift: those whose roots
/// lie within its extent plus twice theirs, or within the two extents plus its gap (`offset` times
/// its extent), with a slack for rounding. Found by a sweep along x; each list sorted.
std::vector<std::vector<int32_t>> lower_neighbours(const std::vector<Vec> &roots, const std::vector<double> &extents,
                                                   const std::vector<int32_t> &rank, double offset) {
  const size_t n = roots.size();
  const std::vector<int32_t> by_x = order_by_x(roots);
  const double largest = n ? *std::max_element(extents.begin(), extents.end()) : 0.0;
  const auto reach = [&](size_t high, size_t low) {
    const double r = std::max(extents[high] + 2.0 * extents[low], (1.0 + offset) * extents[high] + extents[low]);
    return r * (1.0 + 1e-9) + 1e-9 * (roots[high].cwiseAbs().maxCoeff() + roots[low].cwiseAbs().maxCoeff());
  };
  std::vector<std::vector<int32_t>> out(n);
  for (size_t a = 0; a < n; ++a) {
    const size_t i = size_t(by_x[a]);
    const double window =
        2.0 * (1.0 + offset) * (extents[i] + largest) * (1.0 + 1e-6) + 1e-6 * roots[i].cwiseAbs().maxCoeff();
    for (size_t b = a + 1; b < n; ++b) {
      const size_t j = size_t(by_x[b]);
      if (roots[j].x() - roots[i].x() > window) break;
      const bool i_high = rank[i] > rank[j];
      const size_t high = i_high ? i : j, low = i_high ? j : i;
      if ((roots[j] - roots[i]).norm() <= reach(high, low)) out[high].push_back(int32_t(low));
    }
  }
  for (std::vector<int32_t> &list : out) std::sort(list.begin(), list.end());
  return out;
}

}  // namespace

LayerOrder layer_order_from_coverage(const CoatFrame &rest, const FeatherRanges &ranges,
                                     std::span<const LayerKey> keys, const MeshQuery *rest_skin) {
  const size_t n = ranges.size();
  if (!keys.empty() && keys.size() != n)
    throw InternalError("layer_order_from_coverage: " + std::to_string(keys.size()) + " keys for " +
                        std::to_string(n) + " feathers");
  std::vector<FeatherVanes> vanes(n);
  std::vector<Vec> roots(n);
  std::vector<double> extents(n);
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t i = 0; i < int64_t(n); ++i) {
    vanes[size_t(i)] = feather_vanes(rest, ranges, size_t(i), 0.0f);
    roots[size_t(i)] = vanes[size_t(i)].root;
    extents[size_t(i)] = vanes[size_t(i)].extent;
  }
  const GroupTree tree(vanes);
  // Whether the ray from `origin` along the unit `direction` meets group g of feather i's vanes
  // within i's extent (farther than `from`): boxes first, then Moller-Trumbore. The ray meets i's
  // vanes when it meets one of its groups.
  const auto meets = [&](const Vec &origin, const Vec &direction, size_t i, size_t g, double from) {
    const FeatherVanes &f = vanes[i];
    const Vec end = origin + f.extent * direction;
    if (!segment_meets_box(origin, end, f.group_boxes[g]) || !segment_meets_box(origin, end, f.box)) return false;
    const size_t group_end = std::min(f.triangles.size(), g * kGroup + kGroup);
    for (size_t k = g * kGroup; k < group_end; ++k) {
      const double along = ray_crossing(origin, direction, f.triangles[k]);
      if (along > from && along <= extents[i]) return true;
    }
    return false;
  };
  // root_covered_by[j]: the feathers whose vanes cover j's root (the ray from the root along the skin
  // normal meets them, their spheres (root, extent) meeting j's). over[j]: per feather i met on the
  // way out from a vertex of j's vanes outside its root disc (along the skin normal at the vertex's
  // closest skin point, as the checker takes it), the nearest such vertex to j's root (a fraction of
  // j's extent): i lies over j there. Only feathers within twice the two extents of j's root are
  // asked: a vertex of j lies within j's extent of its root, and where the way out meets i it is
  // within i's extent of the vertex and of i's root.
  std::vector<std::vector<int32_t>> root_covered_by(n);
  std::vector<std::vector<std::pair<int32_t, double>>> over(n);
#pragma omp parallel
  {
    std::vector<double> nearest(n, 2.0);  // per feather met from j's vertices: the nearest one's from_root
    std::vector<int32_t> met;             // those feathers
    std::vector<std::pair<double, int64_t>> by_distance;  // j's vertices outside its root disc, from_root
    std::vector<size_t> covering(n, SIZE_MAX);  // per feather: the last j whose root it was found to cover
#pragma omp for schedule(dynamic, 16)
    for (int64_t fj = 0; fj < int64_t(n); ++fj) {
      const size_t j = size_t(fj);
      const Vec origin = roots[j], direction = rest.root_frames[j].normal().cast<double>();
      tree.for_each_met(origin, direction, [&](size_t i, size_t g) {
        if (i == j || covering[i] == j || (roots[i] - roots[j]).norm() > extents[i] + extents[j]) return;
        if (meets(origin, direction, i, g, 0.0)) {
          covering[i] = j;
          root_covered_by[j].push_back(int32_t(i));
        }
      });
      std::sort(root_covered_by[j].begin(), root_covered_by[j].end());
      if (!rest_skin) continue;
      const int64_t v0 = ranges.first_vertex[j], v1 = ranges.first_vertex[j + 1];
      if (v0 == v1 || ranges.first_triangle[j] == ranges.first_triangle[j + 1]) continue;
      const Vec base =
          rest.vanes.positions[size_t(rest.vanes.triangles[size_t(ranges.first_triangle[j])][0])].cast<double>();
      double from_base = 0.0;
      for (int64_t x = v0; x < v1; ++x)
        from_base = std::max(from_base, (rest.vanes.positions[size_t(x)].cast<double>() - base).norm());
      const double thickness = 1e-4 * extents[j];
      // Nearest the root first: a feather met from a vertex is not asked again from a farther one.
      by_distance.clear();
      for (int64_t x = v0; x < v1; ++x) {
        const Vec p = rest.vanes.positions[size_t(x)].cast<double>();
        if ((p - base).norm() <= kCheckerRootDisc * from_base) continue;
        by_distance.emplace_back((p - roots[j]).norm() / std::max(extents[j], 1e-300), x);
      }
      std::sort(by_distance.begin(), by_distance.end());
      met.clear();
      for (const auto &[from_root, x] : by_distance) {
        const Vec p = rest.vanes.positions[size_t(x)].cast<double>();
        const Vec out =
            surface_normal(rest_skin->mesh(), rest_skin->closest(rest.vanes.positions[size_t(x)])).cast<double>();
        tree.for_each_met(p, out, [&](size_t i, size_t g) {
          if (i == j || !(from_root < nearest[i])) return;
          if ((roots[i] - roots[j]).norm() > 2.0 * extents[i] + 2.0 * extents[j]) return;
          if (!meets(p, out, i, g, thickness)) return;
          if (nearest[i] == 2.0) met.push_back(int32_t(i));
          nearest[i] = from_root;
        });
      }
      std::sort(met.begin(), met.end());
      for (const int32_t i : met) {
        if (nearest[size_t(i)] <= 1.0) over[j].emplace_back(i, nearest[size_t(i)]);
        nearest[size_t(i)] = 2.0;
      }
    }
  }
  std::vector<std::vector<int32_t>> covers(n);  // per feather, the roots its vanes cover (ascending)
  for (size_t j = 0; j < n; ++j)
    for (const int32_t i : root_covered_by[j]) covers[size_t(i)].push_back(int32_t(j));
  // Where a feather lies over another's vertices and not under it anywhere (nor over its root the
  // other way), it lies above it. Pairs seen both ways (interleaved, or crossing): the one met
  // nearer its root lies below (a turn about its root cannot take that part out).
  std::vector<std::vector<int32_t>> lies_over(n);  // beyond the roots' coverings
  for (size_t j = 0; j < n; ++j)
    for (const auto &[i, nearer] : over[j]) {
      const auto &back = over[size_t(i)];
      const auto other = std::find_if(back.begin(), back.end(), [&](const auto &e) { return e.first == int32_t(j); });
      const double against = other == back.end() ? 2.0 : other->second;
      if (std::binary_search(covers[j].begin(), covers[j].end(), int32_t(i))) continue;  // j covers i's root
      if (std::binary_search(covers[size_t(i)].begin(), covers[size_t(i)].end(), int32_t(j))) continue;  // kept
      if (nearer < against || (nearer == against && i > int32_t(j))) lies_over[size_t(i)].push_back(int32_t(j));
    }

  LayerOrder order;
  const LayerKey plain;
  const auto key = [&](size_t i) -> const LayerKey & { return keys.empty() ? plain : keys[i]; };
  // Per feather, the feathers it lies above (roots' coverings first, then the rest), and how many of
  // each it still has to wait for.
  std::vector<std::vector<int32_t>> above(n), covered_by(n);
  std::vector<int32_t> root_count(n), remaining_roots(n), remaining(n);
  for (size_t i = 0; i < n; ++i) {
    order.coverings += int64_t(covers[i].size());
    // A covering the keys reverse does not count: the covering feather goes below.
    std::erase_if(covers[i], [&](int32_t j) {
      const bool reversed = key(i) < key(size_t(j));
      if (reversed) order.overridden.emplace_back(int32_t(i), j);
      return reversed;
    });
    std::sort(lies_over[i].begin(), lies_over[i].end());
    std::erase_if(lies_over[i], [&](int32_t j) { return key(i) < key(size_t(j)); });
    root_count[i] = remaining_roots[i] = int32_t(covers[i].size());
    above[i] = covers[i];
    above[i].insert(above[i].end(), lies_over[i].begin(), lies_over[i].end());
    remaining[i] = int32_t(above[i].size());
    for (size_t k = 0; k < above[i].size(); ++k) covered_by[size_t(above[i][k])].push_back(int32_t(i));
  }
  // Next: the smallest key, then the fewest roots' coverings of feathers still to place (a cycle is
  // broken among the other overlaps first), then the fewest of any, then the index.
  using Entry = std::tuple<LayerKey, int32_t, int32_t, int32_t>;
  std::set<Entry> ready;
  for (size_t i = 0; i < n; ++i) ready.emplace(key(i), remaining_roots[i], remaining[i], int32_t(i));
  std::vector<bool> placed(n, false);
  order.rank.assign(n, -1);
  while (!ready.empty()) {
    const auto [k, roots_left, count, i] = *ready.begin();
    ready.erase(ready.begin());
    if (count > 0)
      for (size_t m = 0; m < above[size_t(i)].size(); ++m) {
        const int32_t j = above[size_t(i)][m];
        if (placed[size_t(j)]) continue;
        (int32_t(m) < root_count[size_t(i)] ? order.broken : order.loose).emplace_back(i, j);
      }
    placed[size_t(i)] = true;
    order.rank[size_t(i)] = int32_t(order.bottom_up.size());
    order.bottom_up.push_back(i);
    for (const int32_t c : covered_by[size_t(i)]) {
      if (placed[size_t(c)]) continue;
      const size_t cc = size_t(c);
      ready.erase({key(cc), remaining_roots[cc], remaining[cc], c});
      if (std::binary_search(covers[cc].begin(), covers[cc].end(), i)) --remaining_roots[cc];
      ready.emplace(key(cc), remaining_roots[cc], --remaining[cc], c);
    }
  }
  std::sort(order.loose.begin(), order.loose.end());
  return order;
}

LayeringStats lift_layers(const LayerOrder &order, const FeatherRanges &ranges, const LayeringOptions &options,
                          const MeshQuery *skin, CoatFrame &r_frame, const skin::SkinGrid *skin_grid,
                          const LayeringWarmStart &warm, LayeringState *r_state) {
  const size_t n = ranges.size();
  const LayeringState *previous = warm.previous && !warm.previous->empty() ? warm.previous : nullptr;
  if (previous && (previous->turns.size() != n || previous->scales.size() != n))
    throw InputError("feathers: the layering pass's state of the frame before holds " +
                     std::to_string(previous->turns.size()) + " feathers, expected the coat's " + std::to_string(n));
  if (previous && !previous->yaws.empty() && previous->yaws.size() != n)
    throw InputError("feathers: the layering pass's state of the frame before holds " +
                     std::to_string(previous->yaws.size()) + " yaws, expected the coat's " + std::to_string(n) +
                     " feathers");
  if (previous && (previous->bends.size() != previous->bend_starts.size() ||
                   (!previous->bends.empty() && previous->bends.size() != n)))
    throw InputError("feathers: the layering pass's state of the frame before holds " +
                     std::to_string(previous->bends.size()) + " bends and " +
                     std::to_string(previous->bend_starts.size()) + " bend starts, expected the coat's " +
                     std::to_string(n) + " feathers");
  if (previous && warm.rachis_widths.size() != n)
    throw InternalError("lift_layers: " + std::to_string(warm.rachis_widths.size()) + " rachis widths for " +
                        std::to_string(n) + " feathers");
  if (r_state) {
    r_state->turns.assign(n, 0.0f);
    r_state->scales.assign(n, 1.0f);
    r_state->yaws.assign(n, 0.0f);
    r_state->bends.assign(n, 0.0f);
    r_state->bend_starts.assign(n, 0.0f);
  }
  LayeringStats stats;
  if (n == 0) return stats;
  std::vector<Vec> roots(n);
  std::vector<double> extents(n);
  for (size_t i = 0; i < n; ++i) {
    roots[i] = r_frame.root_frames[i].origin.cast<double>();
    double extent = 0.0;
    for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
      extent = std::max(extent, (r_frame.vanes.positions[size_t(x)].cast<double>() - roots[i]).norm());
    extents[i] = extent;
  }
  // Lifting turns a feather about its root (or shrinks it toward it), so its sphere (root, extent)
  // holds it at any lift. A lower feather can come within the gap of it only when their spheres are
  // within that gap; it can be over a vertex of it (met on the way out within the lower feather's
  // extent) only when the roots are within the higher extent plus twice the lower one.
  const std::vector<std::vector<int32_t>> below = lower_neighbours(roots, extents, order.rank, double(options.offset));
  std::vector<int32_t> level(n, 0);
  int levels = 0;
  for (const int32_t i : order.bottom_up) {
    int l = 0;
    for (const int32_t j : below[size_t(i)]) l = std::max(l, level[size_t(j)] + 1);
    level[size_t(i)] = l;
    levels = std::max(levels, l + 1);
  }
  stats.waves = levels;

  // A feather is placed as soon as every lower feather it may touch is (not wave by wave: a wave's
  // end made every thread wait for the slowest feather of it, and the bird has hundreds of waves).
  // It reads only those feathers' final vanes, so the result is the same for any schedule. Of the
  // feathers ready, the one with the longest chain of feathers waiting above it goes first, so the
  // threads are not left waiting at the end of a long chain.
  std::vector<std::vector<int32_t>> higher(n);
  std::vector<int32_t> waiting(n, 0);
  for (size_t i = 0; i < n; ++i) {
    waiting[i] = int32_t(below[i].size());
    for (const int32_t j : below[i]) higher[size_t(j)].push_back(int32_t(i));
  }
  std::vector<int32_t> chain(n, 0);  // the longest chain of feathers waiting on each, itself included
  for (auto it = order.bottom_up.rbegin(); it != order.bottom_up.rend(); ++it) {
    int32_t c = 0;
    for (const int32_t k : higher[size_t(*it)]) c = std::max(c, chain[size_t(k)]);
    chain[size_t(*it)] = c + 1;
  }
  const auto later = [&](int32_t a, int32_t b) {
    return chain[size_t(a)] < chain[size_t(b)] || (chain[size_t(a)] == chain[size_t(b)] && a > b);
  };
  std::priority_queue<int32_t, std::vector<int32_t>, decltype(later)> ready(later);
  for (size_t i = 0; i < n; ++i)
    if (waiting[i] == 0) ready.push(int32_t(i));
  std::mutex mutex;  // guards ready, waiting and done
  std::condition_variable woken;  // when a feather is ready or the last is done
  size_t done = 0;
  // Each feather's vanes once it is placed: what the feathers above it keep clear of.
  std::vector<FeatherVanes> placed(n);
  // The skin's closest points, searched near the last one found for the same vertex.
  std::optional<skin::SkinGrid> own_grid;
  const skin::SkinGrid *grid = skin_grid;
  if (skin && !grid) grid = &own_grid.emplace(skin->mesh(), *skin);
  // The skin's vertices in a tree, and its longest edge: the skin point closest to a vertex of a
  // feather lies on a triangle whose corners are near the feather's root (normal_cone below).
  SkinVertices skin_vertices;
  std::optional<SkinVertexTree> skin_vertex_tree;
  double longest_edge = 0.0;
  if (skin && !skin->mesh().positions.empty()) {
    const Mesh &mesh = skin->mesh();
    skin_vertices.positions = &mesh.positions;
    skin_vertex_tree.emplace(3, skin_vertices, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    skin_vertex_tree->buildIndex();
    for (const Eigen::Vector3i &t : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        longest_edge = std::max(
            longest_edge, double((mesh.positions[size_t(t[k])] - mesh.positions[size_t(t[(k + 1) % 3])]).norm()));
  }
  int64_t lifted = 0, unresolved = 0, left_under = 0, aside_count = 0, bent = 0;
  std::vector<char> unordered(n, 0);
  float largest = 0.0f;
#pragma omp parallel reduction(+ : lifted, unresolved, left_under, aside_count, bent) reduction(max : largest)
  while (true) {
    int32_t next = -1;
    {
      // A thread with nothing ready sleeps (on a shared machine a spinning one took the time of the
      // one on the longest chain).
      std::unique_lock<std::mutex> lock(mutex);
      woken.wait(lock, [&] { return done == n || !ready.empty(); });
      if (done == n) break;
      next = ready.top();
      ready.pop();
    }
    const size_t i = size_t(next);
    for (int once = 0; once < 1; ++once) {  // `continue` ends the feather
      FeatherVanes &mine = placed[i];
      mine = feather_vanes(r_frame, ranges, i, options.root_disc);
      if (mine.triangles.empty()) continue;
      const double gap = double(options.offset) * mine.extent, gap2 = gap * gap;
      // The axis: across the shaft (root to vane base), lifting toward the skin normal.
      const Vec normal = r_frame.root_frames[i].normal().cast<double>();
      const Vec base = r_frame.vanes.positions[size_t(r_frame.vanes.triangles[size_t(ranges.first_triangle[i])][0])].cast<double>();
      const Vec shaft = base - mine.root;
      const Vec axis_raw = shaft.cross(normal);
      if (!(axis_raw.norm() > 1e-12 * std::max(shaft.norm(), 1e-300))) continue;
      const Vec axis = axis_raw.normalized();
      const double max_angle = std::acos(std::clamp(shaft.normalized().dot(normal), -1.0, 1.0));
      const double cos_max = std::cos(max_angle), sin_max = std::sin(max_angle);
      // A turn about the axis keeps a point's height along the axis and its distance from it, so a
      // group of mine can meet a lower group at some angle only when both differ by at most the
      // sum of their radii and the gap: per group of mine, the lower groups that pass (with a slack
      // for rounding, so a pair skipped is one the sphere test below would reject at every angle).
      struct Candidate {
        const FeatherVanes *feather;
        size_t group;
        // The turns a at which the spheres may meet: cos(a) along + sin(a) across >= least (a
        // shrink tests the spheres themselves)
        double along, across, least;
      };
      auto ring = [&](const Vec &c) {
        const Vec d = c - mine.root;
        const double h = d.dot(axis);
        return Eigen::Vector2d(h, (d - h * axis).norm());
      };
      std::vector<Eigen::Vector2d> mine_rings(mine.centers.size());
      Eigen::AlignedBox2d rings_box;  // of my groups' rings, with their largest radius
      double largest_radius = 0.0;
      for (size_t g = 0; g < mine.centers.size(); ++g) {
        mine_rings[g] = ring(mine.centers[g]);
        rings_box.extend(mine_rings[g]);
        largest_radius = std::max(largest_radius, mine.radii[g]);
      }
      // Whether the point at `d` from the root, turned by a, comes within `reach` of `center`: with
      // d = h axis + v and w = center - root, the turned point is at the squared distance
      // |d|^2 + |w|^2 - 2 (h axis.w + cos(a) v.w + sin(a) (axis x v).w) from it, so it does where
      // cos(a) r_along + sin(a) r_across >= r_least (with a slack for rounding); false when at no a.
      auto turns_meeting = [&](const Vec &d, const Vec &center, double reach, double &r_along, double &r_across,
                               double &r_least) {
        const Vec w = center - mine.root;
        const double h = d.dot(axis);
        const Vec v = d - h * axis;
        r_along = v.dot(w);
        r_across = axis.cross(v).dot(w);
        const double tolerance = 1e-9 * (d.squaredNorm() + w.squaredNorm() + reach * reach);
        r_least = 0.5 * (d.squaredNorm() + w.squaredNorm() - 2.0 * h * axis.dot(w) - reach * reach) - tolerance;
        // The largest of cos(a) along + sin(a) across for a in [0, max_angle]: the amplitude where
        // its phase lies in there, else at an end.
        const double amplitude = std::hypot(r_along, r_across);
        const double largest = r_across >= 0.0 && r_along >= amplitude * cos_max
                                   ? amplitude
                                   : std::max(r_along, cos_max * r_along + sin_max * r_across);
        return largest >= r_least - tolerance;
      };
      // (A shrink changes both, so the search by shrinking gathers its candidates without it.)
      std::vector<std::vector<Candidate>> candidates;
      const double slack = 1e-9 * (mine.extent + mine.root.cwiseAbs().maxCoeff());
      // My groups by their rings' height along the axis: a lower group is compared only with those
      // whose height is within the largest reach of its own (the others fail the test below).
      std::vector<size_t> by_height(mine.centers.size());
      for (size_t g = 0; g < by_height.size(); ++g) by_height[g] = g;
      std::sort(by_height.begin(), by_height.end(), [&](size_t a, size_t b) {
        return mine_rings[a].x() < mine_rings[b].x() || (mine_rings[a].x() == mine_rings[b].x() && a < b);
      });
      std::vector<double> heights(by_height.size());
      for (size_t m = 0; m < by_height.size(); ++m) heights[m] = mine_rings[by_height[m]].x();
      auto gather = [&](bool turns_only) {
        candidates.assign(mine.centers.size(), {});
        bool any = false;
        for (const int32_t j : below[i]) {
          const FeatherVanes *f = &placed[size_t(j)];
          if (f->triangles.empty() || f->box.exteriorDistance(mine.root) > mine.extent + gap + slack) continue;
          for (size_t k = 0; k < f->centers.size(); ++k) {
            if ((f->centers[k] - mine.root).norm() > mine.extent + f->radii[k] + gap) continue;
            const Eigen::Vector2d other = ring(f->centers[k]);
            size_t first = 0, last = mine.centers.size();
            if (turns_only) {
              const double reach = largest_radius + f->radii[k] + gap + slack;
              if (rings_box.squaredExteriorDistance(other) > reach * reach) continue;
              const double window = reach * (1.0 + 1e-9) + 1e-9 * std::abs(other.x());
              first = size_t(std::lower_bound(heights.begin(), heights.end(), other.x() - window) - heights.begin());
              last = size_t(std::upper_bound(heights.begin(), heights.end(), other.x() + window) - heights.begin());
            }
            for (size_t m = first; m < last; ++m) {
              const size_t g = turns_only ? by_height[m] : m;
              const double reach = mine.radii[g] + f->radii[k] + gap + slack;
              if (turns_only &&
                  (std::abs(other.x() - mine_rings[g].x()) > reach || std::abs(other.y() - mine_rings[g].y()) > reach))
                continue;
              // A shrink keeps the group's center on the segment from the root to it, its radius
              // no larger.
              if (!turns_only) {
                const Vec along = mine.centers[g] - mine.root, to_other = f->centers[k] - mine.root;
                const double t = std::clamp(to_other.dot(along) / std::max(along.squaredNorm(), 1e-300), 0.0, 1.0);
                if ((to_other - t * along).squaredNorm() > reach * reach) continue;
              }
              double along = 0.0, across = 0.0, least = 0.0;
              if (turns_only && !turns_meeting(mine.centers[g] - mine.root, f->centers[k], reach, along, across, least))
                continue;
              candidates[g].push_back({f, k, along, across, least});
              any = true;
            }
          }
        }
        return any;
      };
      // The lower feathers that may be over a vertex of mine, and the vertices (outside the root
      // disc) the way out is followed from.
      std::vector<const FeatherVanes *> lower;
      std::vector<Vec> lower_centers;  // of the lower vanes' boxes, with their half diagonals
      std::vector<double> lower_radii;
      for (const int32_t j : below[i])
        if (!placed[size_t(j)].triangles.empty()) {
          const FeatherVanes &f = placed[size_t(j)];
          lower.push_back(&f);
          lower_centers.push_back(f.box.center());
          lower_radii.push_back(0.5 * (f.box.max() - f.box.min()).norm() * (1.0 + 1e-9));
        }
      std::vector<int64_t> outward;
      {
        double from_base = 0.0;
        for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
          from_base = std::max(from_base, (r_frame.vanes.positions[size_t(x)].cast<double>() - base).norm());
        for (int64_t x = ranges.first_vertex[i]; x < ranges.first_vertex[i + 1]; ++x)
          if ((r_frame.vanes.positions[size_t(x)].cast<double>() - base).norm() > double(options.root_disc) * from_base)
            outward.push_back(x);
      }
      // Per such vertex, the lower feathers it may lie under at some turn: the turn keeps the vertex
      // on a circle about the axis, and a lower feather over it is met within its extent, inside its
      // bounding sphere, so the circle passes within the two of the sphere's center (with a slack
      // for rounding). `outward_lower` lists them (places in `lower`) from `outward_first[k]`.
      std::vector<int32_t> outward_lower;
      std::vector<size_t> outward_first(outward.size() + 1, 0);
      std::vector<Eigen::Vector2d> lower_rings(lower.size());
      for (size_t l = 0; l < lower.size(); ++l) lower_rings[l] = ring(lower_centers[l]);
      std::vector<Eigen::Vector2d> outward_rings(outward.size());
      Eigen::AlignedBox2d outward_box;  // of the vertices' rings
      for (size_t k = 0; k < outward.size(); ++k) {
        outward_rings[k] = ring(r_frame.vanes.positions[size_t(outward[k])].cast<double>());
        outward_box.extend(outward_rings[k]);
      }
      std::vector<size_t> near_lower;  // the lower feathers within reach of some vertex's ring's box
      for (size_t l = 0; l < lower.size(); ++l) {
        const double reach = lower[l]->extent + lower_radii[l] + slack;
        if (!outward_box.isEmpty() && outward_box.squaredExteriorDistance(lower_rings[l]) <= reach * reach)
          near_lower.push_back(l);
      }
      for (size_t k = 0; k < outward.size(); ++k) {
        const Eigen::Vector2d &at = outward_rings[k];
        for (const size_t l : near_lower) {
          const double reach = lower[l]->extent + lower_radii[l] + slack;
          if ((lower_rings[l] - at).squaredNorm() <= reach * reach) outward_lower.push_back(int32_t(l));
        }
        outward_first[k + 1] = outward_lower.size();
      }
      if (!gather(true) && outward_lower.empty()) continue;
      std::vector<Triangle> moved(mine.triangles.size());
      std::vector<Eigen::AlignedBox3d> moved_boxes(mine.triangles.size());
      // The last conflict found of each kind (a pair of triangle groups, a vertex below the skin, a
      // vertex under a lower feather) is tried first: the search's next angle is near, so it usually
      // conflicts again and the answer comes at once. The answer is the full test's either way (every
      // test skipped is conservative).
      struct Witness {
        bool pair = false;  // a group of mine against a candidate
        size_t group = 0, candidate = 0;
        bool below = false;  // a vertex below the skin
        int64_t vertex = 0;
        bool under = false;  // a vertex (its place in `outward`) under a lower feather
        size_t outward = 0;
      } witness;
      size_t call = 0;
      std::vector<size_t> turned_in(mine.centers.size(), SIZE_MAX);  // the call that turned a group
      std::vector<Eigen::AlignedBox3d> moved_group_boxes(mine.centers.size());
      const auto apart = [&](const Eigen::AlignedBox3d &a, const Eigen::AlignedBox3d &b) {
        return (a.min().array() > b.max().array() + gap).any() || (b.min().array() > a.max().array() + gap).any();
      };
      auto pair_conflict = [&](const Eigen::Matrix3d &turn, size_t g, size_t c) {
        const size_t end = std::min(mine.triangles.size(), g * kGroup + kGroup);
        if (turned_in[g] != call) {
          moved_group_boxes[g].setEmpty();
          for (size_t t = g * kGroup; t < end; ++t) {
            moved_boxes[t].setEmpty();
            for (int v = 0; v < 3; ++v) {
              moved[t][size_t(v)] = mine.root + turn * (mine.triangles[t][size_t(v)] - mine.root);
              moved_boxes[t].extend(moved[t][size_t(v)]);
            }
            moved_group_boxes[g].extend(moved_boxes[t]);
          }
          turned_in[g] = call;
        }
        const Candidate &k = candidates[g][c];
        const Eigen::AlignedBox3d &other_box = k.feather->group_boxes[k.group];
        if (apart(moved_group_boxes[g], other_box)) return false;
        const size_t other_end = std::min(k.feather->triangles.size(), k.group * kGroup + kGroup);
        for (size_t t = g * kGroup; t < end; ++t) {
          if (apart(moved_boxes[t], other_box)) continue;
          for (size_t u = k.group * kGroup; u < other_end; ++u) {
            if (apart(moved_boxes[t], k.feather->boxes[u])) continue;
            if (too_close(moved[t], k.feather->triangles[u], gap2)) return true;
          }
        }
        return false;
      };
      // Below the skin. On a closed skin the signed distance is the distance with a sign, which
      // changes by at most what a point moves: per vertex, the last distance asked and the turn it
      // was asked at are kept, and a vertex that the new turn cannot move that far from there
      // (the turns' difference bounds the move) stays out without asking again. The slack covers the
      // distance's rounding in float. An open skin (whose sign flips past its open edges) is asked
      // every time.
      const int64_t v0 = ranges.first_vertex[i], v1 = ranges.first_vertex[i + 1];
      const bool closed_skin = skin && skin->open_edges().empty();
      const double skin_slack = 1e-4 * mine.extent + 1e-6 * mine.root.cwiseAbs().maxCoeff();
      // The signed distance to the skin, and in r_near the closest skin point, searched from r_near
      // (the same vertex's last one): in the grid's cells around p when that settles it, else in the
      // skin's tree from there.
      auto skin_distance = [&](const Vec &p, SurfacePoint &r_near) {
        float distance = 0.0f;
        SurfacePoint found;
        if (grid->local_signed_distance(p.cast<float>(), int(r_near.triangle), distance, found)) {
          r_near = found;
          return double(distance);
        }
        SurfacePoint hint = r_near;
        return skin->signed_distance(p, hint, r_near);
      };
      std::vector<SurfacePoint> mine_skin(skin ? size_t(v1 - v0) : 0);  // per vertex: its last closest point
      struct Known {
        double distance, angle, scale;
      };
      std::vector<Known> known;
      auto below_skin = [&](double angle, double scale, const Eigen::Matrix3d &turn, int64_t x) {
        const Vec p = r_frame.vanes.positions[size_t(x)].cast<double>();
        const double from_root = (p - mine.root).norm();
        if (from_root <= double(options.root_disc) * mine.extent) return false;
        if (closed_skin) {
          if (known.empty()) {
            known.resize(size_t(v1 - v0));
            for (int64_t y = v0; y < v1; ++y)
              known[size_t(y - v0)] = {
                  skin_distance(r_frame.vanes.positions[size_t(y)].cast<double>(), mine_skin[size_t(y - v0)]),
                  0.0, 1.0};
          }
          Known &k = known[size_t(x - v0)];
          // |s R(a) - s' R(a')| <= |s - s'| + s' |R(a) - R(a')| = |s - s'| + 2 s' sin(|a - a'| / 2).
          const double move = std::abs(scale - k.scale) + 2.0 * k.scale * std::sin(0.5 * std::abs(angle - k.angle));
          if (k.distance > move * from_root + skin_slack) return false;
          const Vec q = mine.root + turn * (p - mine.root);
          SurfacePoint &near_skin = mine_skin[size_t(x - v0)];
          k = {skin_distance(q, near_skin), angle, scale};
          return k.distance < 0.0;
        }
        const Vec q = mine.root + turn * (p - mine.root);
        SurfacePoint &near_skin = mine_skin[size_t(x - v0)];
        return skin_distance(q, near_skin) < 0.0;
      };
      // Under a lower feather: the way out from a vertex of mine along the skin's normal (at the skin
      // point closest to it, as the checker takes it) meets a lower feather's vanes within that
      // feather's extent. The skin is not asked where the way out enters it again: a lower feather
      // beyond a fold of skin counts too (more turning asked than needed, never less).
      bool under_test = !outward_lower.empty();
      std::vector<SurfacePoint> closest_hints(skin && !outward.empty() ? size_t(v1 - v0) : 0);
      // The directions the way out can take from any vertex of mine, at any move about the root: a
      // cone about `cone_axis` of half angle `cone_angle` holding the skin's vertex normals near the
      // feather. A vertex q lies within the feather's extent of its root, so the skin point closest to
      // it lies within twice that plus the root's distance to the skin, on a triangle
      // whose corners lie within the longest skin edge more; the normal there is a weighted mean of
      // those corners' normals, inside their cone when the cone is narrower than a half space.
      // Built when first needed; cone_known -1: no such cone (every direction is possible).
      int cone_known = 0;
      Vec cone_axis = Vec::Zero();
      double cone_angle = M_PI;
      std::vector<std::pair<uint32_t, float>> near_skin;
      auto normal_cone = [&] {
        cone_known = -1;
        if (!skin_vertex_tree) return;
        const Mesh &mesh = skin->mesh();
        const Eigen::Vector3f root = mine.root.cast<float>();
        const double to_skin = std::abs(double(skin->signed_distance(root)));
        const double radius = (2.0 * mine.extent + to_skin + longest_edge) * (1.0 + 1e-5) +
                              1e-5 * (mine.root.cwiseAbs().maxCoeff() + longest_edge);
        near_skin.clear();
        skin_vertex_tree->radiusSearch(root.data(), float(radius * radius), near_skin,
                                       nanoflann::SearchParams(32, 0.0f, false));
        Vec sum = Vec::Zero();
        for (const auto &[v, distance] : near_skin) {
          const Vec n = mesh.vertex_normals[v].cast<double>();
          if (!(n.norm() > 0.5)) return;  // a vertex without a normal: no bound
          sum += n;
        }
        if (near_skin.empty() || !(sum.norm() > 1e-6)) return;
        cone_axis = sum.normalized();
        double least = 1.0;
        for (const auto &[v, distance] : near_skin)
          least = std::min(least, cone_axis.dot(mesh.vertex_normals[v].cast<double>().normalized()));
        // A slack for the weights' and the normals' rounding in float.
        cone_angle = std::acos(std::clamp(least, -1.0, 1.0)) + 1e-4;
        if (cone_angle < 0.5 * M_PI - 1e-3) cone_known = 1;
      };
      // Whether some direction of the cone, from the origin, passes within `radius` of `w`.
      auto in_cone = [&](const Vec &w, double radius) {
        if (cone_known == 0) normal_cone();
        if (cone_known < 0) return true;
        const double distance = w.norm();
        if (distance <= radius) return true;
        const double reach = cone_angle + std::asin(std::min(1.0, radius / distance)) + 1e-6;
        return reach >= M_PI || cone_axis.dot(w) >= distance * std::cos(reach);
      };
      // With `r_over`, every lower feather over the vertex not marked yet is marked there (by its
      // place in `lower`), and their number returned.
      // The test at `q` (where vertex `x` lies) against the lower feathers listed (places in `lower`)
      // from `first` to `last`.
      auto under_lower_at = [&](const Vec &q, int64_t x, const int32_t *first, const int32_t *last,
                                std::vector<char> *r_over) -> std::ptrdiff_t {
        Vec out = normal;
        bool out_known = !skin;
        std::ptrdiff_t marked = 0;
        for (const int32_t *c = first; c != last; ++c) {
          const size_t l = size_t(*c);
          if (r_over && (*r_over)[l]) continue;
          const FeatherVanes &f = *lower[l];
          const Vec to_center = lower_centers[l] - q;
          const double reach = f.extent + lower_radii[l];
          if (to_center.squaredNorm() > reach * reach) continue;
          if (!out_known) {
            // The way out, whichever its direction, must reach one of the lower vanes' groups
            // before the skin is asked for it.
            bool reachable = false;
            for (size_t g = 0; g < f.centers.size() && !reachable; ++g) {
              const double group_reach = f.extent + f.radii[g] * (1.0 + 1e-9) + slack;
              const Vec to_group = f.centers[g] - q;
              reachable = to_group.squaredNorm() <= group_reach * group_reach &&
                          in_cone(to_group, f.radii[g] * (1.0 + 1e-9) + slack);
            }
            if (!reachable) continue;
            // The closest skin point moves little from one turn to the next: searched from the last.
            SurfacePoint &closest = closest_hints[size_t(x - v0)];
            skin_distance(q, closest);
            out = surface_normal(skin->mesh(), closest).cast<double>();
            out_known = true;
          }
          // The segment's nearest point to the vanes' bounding sphere first, then the boxes.
          const double t = std::clamp(to_center.dot(out), 0.0, f.extent);
          if ((to_center - t * out).squaredNorm() > lower_radii[l] * lower_radii[l]) continue;
          const Vec end = q + f.extent * out;
          if (!segment_meets_box(q, end, f.box)) continue;
          bool hit = false;
          for (size_t g = 0; g < f.group_boxes.size() && !hit; ++g) {
            // The group's sphere (widened for rounding), then its box.
            const Vec to_group = f.centers[g] - q;
            const double along = std::clamp(to_group.dot(out), 0.0, f.extent);
            const double radius = f.radii[g] * (1.0 + 1e-9) + slack;
            if ((to_group - along * out).squaredNorm() > radius * radius) continue;
            if (!segment_meets_box(q, end, f.group_boxes[g])) continue;
            const size_t group_end = std::min(f.triangles.size(), g * kGroup + kGroup);
            for (size_t u = g * kGroup; u < group_end && !hit; ++u) {
              const double along = ray_crossing(q, out, f.triangles[u]);
              hit = along >= 0.0 && along <= f.extent;
            }
          }
          if (!hit) continue;
          if (!r_over) return 1;
          (*r_over)[l] = 1;
          ++marked;
        }
        return marked;
      };
      // At a turn: the vertex outward[k] turned, against the lower feathers its circle passes near.
      auto under_lower = [&](const Eigen::Matrix3d &turn, size_t k,
                             std::vector<char> *r_over = nullptr) -> std::ptrdiff_t {
        const int64_t x = outward[k];
        const Vec q = mine.root + turn * (r_frame.vanes.positions[size_t(x)].cast<double>() - mine.root);
        const int32_t *list = outward_lower.data();
        return under_lower_at(q, x, list + outward_first[k], list + outward_first[k + 1], r_over);
      };
      // With `r_clear`, what the call learnt of the turn without the test for lower feathers over
      // it: 0 it conflicts, 1 it does not, unchanged when the call did not find out.
      auto conflict = [&](double angle, double scale = 1.0, signed char *r_clear = nullptr) {
        const Eigen::Matrix3d turn = scale * Eigen::AngleAxisd(angle, axis).toRotationMatrix();
        ++call;
        const bool turned = angle > 0.0 || scale != 1.0;
        const double cos_angle = std::cos(angle), sin_angle = std::sin(angle);
        const auto blocked = [&] {
          if (r_clear) *r_clear = 0;
          return true;
        };
        // Whether group g of mine and its candidate k may meet: their spheres.
        const auto spheres_meet = [&](size_t g, size_t k) {
          const Candidate &other = candidates[g][k];
          if (scale == 1.0) return cos_angle * other.along + sin_angle * other.across >= other.least;
          const Vec c = mine.root + turn * (mine.centers[g] - mine.root);
          const double reach = mine.radii[g] + other.feather->radii[other.group] + gap;
          return (other.feather->centers[other.group] - c).squaredNorm() <= reach * reach;
        };
        if (witness.pair && spheres_meet(witness.group, witness.candidate) &&
            pair_conflict(turn, witness.group, witness.candidate))
          return blocked();
        if (witness.below && skin && turned && below_skin(angle, scale, turn, witness.vertex)) return blocked();
        if (witness.under && under_test && under_lower(turn, witness.outward)) return true;
        for (size_t g = 0; g < mine.centers.size(); ++g) {
          if (candidates[g].empty()) continue;
          const Vec c = scale == 1.0 ? mine.centers[g] : Vec(mine.root + turn * (mine.centers[g] - mine.root));
          for (size_t k = 0; k < candidates[g].size(); ++k) {
            const Candidate &other = candidates[g][k];
            if (scale == 1.0) {
              if (cos_angle * other.along + sin_angle * other.across < other.least) continue;
            } else {
              const double reach = mine.radii[g] + other.feather->radii[other.group] + gap;
              if ((other.feather->centers[other.group] - c).squaredNorm() > reach * reach) continue;
            }
            if (witness.pair && witness.group == g && witness.candidate == k) continue;  // tried first
            if (pair_conflict(turn, g, k)) {
              witness.pair = true;
              witness.group = g;
              witness.candidate = k;
              return blocked();
            }
          }
        }
        // No vertex of the turned vanes below the skin (vertices near the root, which leaves the skin
        // there, excepted as the root disc is). Last: the triangle tests above are cheaper.
        if (skin && turned)
          for (int64_t x = v0; x < v1; ++x)
            if (!(witness.below && witness.vertex == x) && below_skin(angle, scale, turn, x)) {
              witness.below = true;
              witness.vertex = x;
              return blocked();
            }
        if (r_clear) *r_clear = 1;
        if (under_test)
          for (size_t k = 0; k < outward.size(); ++k)
            if (!(witness.under && witness.outward == k) && under_lower(turn, k)) {
              witness.under = true;
              witness.outward = k;
              return true;
            }
        return false;
      };
      // Where the feather ends: turned by `angle` about the axis (on top of the skin pass's turn), or
      // shrunk toward its root, unturned, to `scale` of its size. Both map each curve point and vane
      // vertex's offset from the root.
      auto move_about_root = [&](const auto &map) {
        const Eigen::Vector3f root = r_frame.root_frames[i].origin;
        for (int64_t p = ranges.first_point[i]; p < ranges.first_point[i + 1]; ++p) {
          Eigen::Vector3f &x = r_frame.curves.curves.positions[size_t(p)];
          x = root + map(Eigen::Vector3f(x - root));
        }
        for (int64_t p = ranges.first_vertex[i]; p < ranges.first_vertex[i + 1]; ++p) {
          Eigen::Vector3f &x = r_frame.vanes.positions[size_t(p)];
          x = root + map(Eigen::Vector3f(x - root));
        }
      };
      // The feather's points moved by a turn of `angle` (and maybe a yaw or a bend): its lift, vanes,
      // counts and state follow.
      auto record_turn = [&](double angle) {
        r_frame.lifts[i] += float(angle);
        mine = feather_vanes(r_frame, ranges, i, options.root_disc);
        ++lifted;
        largest = std::max(largest, float(angle));
        if (r_state) r_state->turns[i] = float(angle);
      };
      auto turn_by = [&](double angle) {
        const Eigen::Matrix3f turn = Eigen::AngleAxisd(angle, axis).toRotationMatrix().cast<float>();
        move_about_root([&](const Eigen::Vector3f &offset) { return Eigen::Vector3f(turn * offset); });
        record_turn(angle);
      };
      auto shrink_to = [&](double size) {
        const float scale = float(size);
        move_about_root([&](const Eigen::Vector3f &offset) { return Eigen::Vector3f(scale * offset); });
        r_frame.scales[i] *= scale;
        mine = feather_vanes(r_frame, ranges, i, options.root_disc);
        ++unresolved;
        unordered[i] = 1;
        if (r_state) r_state->scales[i] = scale;
      };
      // The largest size in [0, cap] at which the feather, unturned, clears. Whether a size clears is
      // not monotone in it (a lower feather lies across the vanes' middle, the skin curves away under
      // the tip), so a bisection over [0, cap] may end far below a size that clears, or at 0: the sizes
      // are scanned down by kShrinkSteps steps of cap / kShrinkSteps, then bisected (12 halvings)
      // between the first that clears and the one above it. Where no step clears, the bisection over
      // [0, the last step] (the feather all but gone: its vanes within the checker's root disc).
      auto largest_clear_size = [&](double cap) {
        gather(false);
        witness = {};
        if (!conflict(0.0, cap)) return cap;
        const double step = cap / kShrinkSteps;
        double lo = 0.0, hi = step;
        for (int k = kShrinkSteps - 1; k >= 1; --k)
          if (!conflict(0.0, k * step)) {
            lo = k * step;
            hi = (k + 1) * step;
            break;
          }
        for (int b = 0; b < 12; ++b) {
          const double mid = 0.5 * (lo + hi);
          (conflict(0.0, mid) ? hi : lo) = mid;
        }
        return lo;
      };
      // Between a value that clears (`clear`) and one that does not (`blocked`), the one nearest
      // `blocked` that clears, by bisection to `tolerance`.
      const auto nearest_clear = [](double clear, double blocked, double tolerance, const auto &clears) {
        while (std::abs(clear - blocked) > tolerance) {
          const double mid = 0.5 * (clear + blocked);
          (clears(mid) ? clear : blocked) = mid;
        }
        return clear;
      };
      const auto clears = [&](double angle) { return !conflict(angle); };
      // The smallest turn in (below, above] that clears, `above` clearing (bisection to `tolerance`
      // radians), and the largest in [below, above), `below` clearing.
      auto lowest_clear = [&](double below, double above, double tolerance = 1e-4) {
        return nearest_clear(above, below, tolerance, clears);
      };
      auto highest_clear = [&](double below, double above, double tolerance = 1e-4) {
        return nearest_clear(below, above, tolerance, clears);
      };
      auto end_at = [&](double angle) {
        if (angle > 0.0) turn_by(angle);
      };
      // How many lower feathers are over it at `angle`, counted up to `enough` (no more is asked).
      // The vertices (places in `outward`) under a lower feather at the last count are asked first, so
      // that a count reaching `enough` stops sooner; below `enough` every vertex is asked, and the
      // count is the same in any order (each lower feather over it counts once).
      std::vector<char> over(lower.size());
      std::vector<size_t> last_under, now_under;
      std::vector<size_t> counted_in(outward.size(), SIZE_MAX);  // the count that asked a vertex
      size_t counts = 0;
      auto under_count = [&](double angle, std::ptrdiff_t enough) {
        std::fill(over.begin(), over.end(), char(0));
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
        ++counts;
        now_under.clear();
        std::ptrdiff_t count = 0;
        const auto ask = [&](size_t k) {
          counted_in[k] = counts;
          const std::ptrdiff_t marked = under_lower(turn, k, &over);
          if (marked > 0) now_under.push_back(k);
          count += marked;
        };
        for (size_t m = 0; m < last_under.size() && count < enough; ++m) ask(last_under[m]);
        for (size_t k = 0; k < outward.size() && count < enough; ++k)
          if (counted_in[k] != counts) ask(k);
        last_under.swap(now_under);
        return count;
      };
      constexpr double kStep = 0.02;  // radians, about 1.1 degrees

      // Turned aside where a turn is not enough (docs/feathers.md, "Turned aside"): a feather no turn
      // about its root takes out from under the lower ones is turned about the skin normal through its
      // root (a yaw, the nearest of kAsideYaws first), then up about its axis turned with it, by the
      // smallest turn (steps of kAsideStep up to the skin normal, then bisection) that keeps it clear of
      // every lower feather's vanes by the offset, out of the skin and from under every lower feather.
      // A yaw and a turn move it rigidly about its root, so it stays within its extent of it and meets
      // only the lower feathers placed before it. Found: the feather ends there, and true; none: false,
      // nothing changed. Tested without the shortcuts of the turns about the axis, with those of any
      // move about the root (clear_moved).
      std::vector<Vec> aside_vertices;
      bool counted_under = false;  // whether the feather was counted in left_under
      // A yaw and a turn move the feather rigidly about its root: each point keeps its distance from
      // it. So only the lower feathers whose vanes' boxes come within the feather's extent plus the
      // gap of its root (with the slack for rounding) can meet it (`aside_near`, places in `lower`,
      // ascending), and a vertex of mine can lie under a lower feather only when its distance from the
      // root and that of the lower vanes' bounding sphere's center differ by at most the sphere's
      // radius plus the lower extent: per vertex in `outward`, the lower feathers that pass,
      // ascending, from aside_under_first[k]. Built on the first move tested; every test they skip
      // is one the full test rejects, so the answers are the same.
      std::vector<size_t> aside_near;
      std::vector<int32_t> every_lower(lower.size());  // places in `lower`: a bent vertex is asked against all
      for (size_t l = 0; l < lower.size(); ++l) every_lower[l] = int32_t(l);
      std::vector<int32_t> aside_under;
      std::vector<size_t> aside_under_first;
      auto aside_candidates = [&] {
        for (size_t l = 0; l < lower.size(); ++l)
          if (lower[l]->box.exteriorDistance(mine.root) <= mine.extent + gap + slack) aside_near.push_back(l);
        aside_under_first.assign(1, 0);
        std::vector<double> lower_from_root(lower.size());
        for (size_t l = 0; l < lower.size(); ++l) lower_from_root[l] = (lower_centers[l] - mine.root).norm();
        for (const int64_t x : outward) {
          const double from_root = (r_frame.vanes.positions[size_t(x)].cast<double>() - mine.root).norm();
          for (size_t l = 0; l < lower.size(); ++l)
            if (std::abs(lower_from_root[l] - from_root) <= lower[l]->extent + lower_radii[l] + slack)
              aside_under.push_back(int32_t(l));
          aside_under_first.push_back(aside_under.size());
        }
      };
      // The lower feather whose vanes met the last move tested (the next is near): tried first. So are
      // the vertex last found below the skin and the vertex (its place in `outward`) last found under
      // a lower feather.
      size_t aside_witness = SIZE_MAX, aside_below = SIZE_MAX, aside_under_witness = SIZE_MAX;
      std::vector<Triangle> aside_triangles(mine.triangles.size());
      std::vector<Eigen::AlignedBox3d> aside_boxes(mine.triangles.size());
      std::vector<Eigen::AlignedBox3d> aside_group_boxes(mine.group_boxes.size());
      std::vector<size_t> aside_turned_in(mine.group_boxes.size(), SIZE_MAX);  // the move that turned a group
      // Per group, the box of its bounding sphere moved (a group's triangles lie in it), and of them all.
      std::vector<Eigen::AlignedBox3d> aside_sphere_boxes(mine.group_boxes.size());
      size_t aside_call = 0;
      // Per vertex, where the skin was last asked for it by a move and its signed distance there.
      std::vector<std::pair<Vec, double>> aside_known;
      // `moved_point` maps a point of the feather (world, double) to where the move takes it. A rigid
      // move keeps each point's distance from the root (so a group's sphere moves whole, and a vertex
      // is asked only against the lower feathers at its distance); a bend does not: its groups' boxes
      // are those of their moved triangles, every vertex is asked against every lower feather, and a
      // bend that takes a vertex farther from the root than the feather's extent is refused (the
      // schedule's spheres hold the feather). `under_too` false: the test for lower feathers over it
      // is skipped.
      const auto clear_mapped = [&](const auto &moved_point, bool rigid, bool under_too) {
        if (aside_under_first.empty()) aside_candidates();
        ++aside_call;
        // A group of mine is moved when first tested.
        const auto move_group = [&](size_t m) {
          if (aside_turned_in[m] == aside_call) return;
          aside_turned_in[m] = aside_call;
          aside_group_boxes[m].setEmpty();
          const size_t end = std::min(mine.triangles.size(), m * kGroup + kGroup);
          for (size_t t = m * kGroup; t < end; ++t) {
            aside_boxes[t].setEmpty();
            for (size_t v = 0; v < 3; ++v) {
              aside_triangles[t][v] = moved_point(mine.triangles[t][v]);
              aside_boxes[t].extend(aside_triangles[t][v]);
            }
            aside_group_boxes[m].extend(aside_boxes[t]);
          }
        };
        Eigen::AlignedBox3d all;
        if (rigid) {
          for (size_t m = 0; m < mine.centers.size(); ++m) {
            const Vec c = moved_point(mine.centers[m]);
            const double r = mine.radii[m] * (1.0 + 1e-9) + slack;
            aside_sphere_boxes[m] = Eigen::AlignedBox3d(c.array() - r, c.array() + r);
            all.extend(aside_sphere_boxes[m]);
          }
        } else {
          for (int64_t x = v0; x < v1; ++x)
            if ((moved_point(r_frame.vanes.positions[size_t(x)].cast<double>()) - mine.root).norm() > mine.extent)
              return false;
          for (size_t m = 0; m < mine.centers.size(); ++m) {
            move_group(m);
            aside_sphere_boxes[m] = aside_group_boxes[m];
            all.extend(aside_sphere_boxes[m]);
          }
        }
        // A triangle's box lies in its group's, so a pair of triangles whose groups' boxes are apart is
        // apart too.
        const auto vanes_meet = [&](size_t l) {
          const FeatherVanes &f = *lower[l];
          if (apart(all, f.box)) return false;
          for (size_t m = 0; m < mine.centers.size(); ++m) {
            if (apart(aside_sphere_boxes[m], f.box)) continue;
            move_group(m);
            if (apart(aside_group_boxes[m], f.box)) continue;
            const size_t mine_end = std::min(aside_triangles.size(), m * kGroup + kGroup);
            for (size_t g = 0; g < f.group_boxes.size(); ++g) {
              if (apart(aside_group_boxes[m], f.group_boxes[g])) continue;
              const size_t group_end = std::min(f.triangles.size(), g * kGroup + kGroup);
              for (size_t t = m * kGroup; t < mine_end; ++t) {
                if (apart(aside_boxes[t], f.group_boxes[g])) continue;
                for (size_t u = g * kGroup; u < group_end; ++u)
                  if (!apart(aside_boxes[t], f.boxes[u]) && too_close(aside_triangles[t], f.triangles[u], gap2))
                    return true;
              }
            }
          }
          return false;
        };
        aside_vertices.resize(size_t(v1 - v0));
        if (closed_skin && aside_known.empty()) aside_known.assign(size_t(v1 - v0), {Vec::Zero(), -1.0});
        const auto below = [&](int64_t x) {
          const Vec p = r_frame.vanes.positions[size_t(x)].cast<double>();
          if ((p - mine.root).norm() <= double(options.root_disc) * mine.extent) return false;
          const Vec &q = aside_vertices[size_t(x - v0)];
          // On a closed skin, a vertex that has not moved as far as it was from the skin the last
          // time it was asked here is still out (as below_skin's bound).
          if (closed_skin) {
            auto &[last, distance] = aside_known[size_t(x - v0)];
            if (distance > (q - last).norm() + skin_slack) return false;
            last = q;
            distance = skin_distance(q, mine_skin[size_t(x - v0)]);
            return distance < 0.0;
          }
          return skin_distance(q, mine_skin[size_t(x - v0)]) < 0.0;
        };
        const auto under = [&](size_t k) {
          const int64_t x = outward[k];
          if (!rigid)
            return under_lower_at(aside_vertices[size_t(x - v0)], x, every_lower.data(),
                                  every_lower.data() + every_lower.size(), nullptr) != 0;
          const int32_t *list = aside_under.data();
          return under_lower_at(aside_vertices[size_t(x - v0)], x, list + aside_under_first[k],
                                list + aside_under_first[k + 1], nullptr) != 0;
        };
        const auto move_vertex = [&](int64_t x) {
          aside_vertices[size_t(x - v0)] = moved_point(r_frame.vanes.positions[size_t(x)].cast<double>());
        };
        // The three tests must all pass: the last conflict of each kind is tried first, whichever
        // kind met last (a move clear of the vanes is often still under a lower feather).
        if (aside_witness != SIZE_MAX && vanes_meet(aside_witness)) return false;
        if (skin && aside_below != SIZE_MAX) {
          move_vertex(int64_t(aside_below));
          if (below(int64_t(aside_below))) return false;
        }
        if (under_too && aside_under_witness != SIZE_MAX) {
          move_vertex(outward[aside_under_witness]);
          if (under(aside_under_witness)) return false;
        }
        for (const size_t l : aside_near)
          if (l != aside_witness && vanes_meet(l)) {
            aside_witness = l;
            return false;
          }
        for (int64_t x = v0; x < v1; ++x) move_vertex(x);
        if (skin)
          for (int64_t x = v0; x < v1; ++x)
            if (size_t(x) != aside_below && below(x)) {
              aside_below = size_t(x);
              return false;
            }
        if (under_too)
          for (size_t k = 0; k < outward.size(); ++k)
            if (k != aside_under_witness && under(k)) {
              aside_under_witness = k;
              return false;
            }
        return true;
      };
      auto clear_moved = [&](const Eigen::Matrix3d &move) {
        return clear_mapped([&](const Vec &p) { return Vec(mine.root + move * (p - mine.root)); }, true, true);
      };
      // The move of a feather turned aside: the yaw about the skin normal, then the turn about the axis
      // turned with it.
      auto aside_move = [&](double yaw, double angle) {
        const Eigen::Matrix3d aside = Eigen::AngleAxisd(yaw, normal).toRotationMatrix();
        return Eigen::Matrix3d(Eigen::AngleAxisd(angle, aside * axis).toRotationMatrix() * aside);
      };
      // Whether the feather turned aside by `yaw`, then turned by `angle`, keeps clear of the lower vanes
      // and the skin (the test for lower feathers over it skipped).
      auto clear_aside_only = [&](double yaw, double angle) {
        const Eigen::Matrix3d move = aside_move(yaw, angle);
        return clear_mapped([&](const Vec &p) { return Vec(mine.root + move * (p - mine.root)); }, true, false);
      };
      // The lower feathers over it as a move clear of their vanes and the skin (clear_mapped, true) left
      // it, counted up to `enough`: every vertex was moved by that test.
      std::vector<char> over_moved(lower.size());
      const auto count_moved = [&](std::ptrdiff_t enough) {
        std::fill(over_moved.begin(), over_moved.end(), char(0));
        std::ptrdiff_t count = 0;
        for (size_t k = 0; k < outward.size() && count < enough; ++k)
          count += under_lower_at(aside_vertices[size_t(outward[k] - v0)], outward[k], every_lower.data(),
                                  every_lower.data() + every_lower.size(), &over_moved);
        return count;
      };
      // The feather ends out from under every lower feather, or left under one (named, counted once).
      auto end_out = [&](bool out) {
        if (out) {
          if (counted_under) --left_under;
          unordered[i] = 0;
        } else {
          if (!counted_under) ++left_under;
          counted_under = true;
          unordered[i] = 1;
        }
      };
      // `out`: out from under every lower feather (turned aside), else left under one (named).
      auto end_aside = [&](double yaw, double angle, bool out = true) {
        const Eigen::Matrix3f m = aside_move(yaw, angle).cast<float>();
        move_about_root([&](const Eigen::Vector3f &offset) { return Eigen::Vector3f(m * offset); });
        record_turn(angle);
        if (r_state) r_state->yaws[i] = float(yaw);
        if (out) ++aside_count;
        end_out(out);
      };
      // The smallest turn in [0, max_angle] at which `clears` holds, by steps of kAsideStep, then
      // bisection to kAsideTolerance; -1 when no step clears.
      auto smallest_clear_step = [&](const auto &clears) {
        double failing = -1.0, clearing = -1.0;
        for (double a = 0.0; a < max_angle + kAsideStep; a += kAsideStep) {
          const double at = std::min(a, max_angle);
          if (clears(at)) {
            clearing = at;
            break;
          }
          failing = at;
        }
        if (clearing >= 0.0 && failing >= 0.0) clearing = nearest_clear(clearing, failing, kAsideTolerance, clears);
        return clearing;
      };
      // The turn in [0, max_angle] nearest `from` at which `clears` holds: `from` itself, else by steps
      // of `step` either way (up first at each step), then bisection to kAsideTolerance toward the step
      // before; -1 when no step clears.
      auto nearest_clear_step = [&](double from, double step, const auto &clears) {
        if (clears(from)) return from;
        double last_up = from, last_down = from;
        for (int s = 1; last_up < max_angle || last_down > 0.0; ++s) {
          const double up = std::min(from + s * step, max_angle), down = std::max(from - s * step, 0.0);
          if (up > last_up) {
            if (clears(up)) return nearest_clear(up, last_up, kAsideTolerance, clears);
            last_up = up;
          }
          if (down < last_down) {
            if (clears(down)) return nearest_clear(down, last_down, kAsideTolerance, clears);
            last_down = down;
          }
        }
        return -1.0;
      };
      // The yaws tried, nearest `preferred` first (the yaw of the frame before; 0: the smallest first,
      // the positive one of a pair first).
      auto turn_aside = [&](double preferred) {
        if (lower.empty() || outward.empty()) return false;
        std::array<double, std::size(kAsideYaws)> yaws;
        std::copy(std::begin(kAsideYaws), std::end(kAsideYaws), yaws.begin());
        std::stable_sort(yaws.begin(), yaws.end(),
                         [&](double a, double b) { return std::abs(a - preferred) < std::abs(b - preferred); });
        for (const double yaw : yaws) {
          const double clearing = smallest_clear_step([&](double a) { return clear_moved(aside_move(yaw, a)); });
          if (clearing < 0.0) continue;
          end_aside(yaw, clearing);
          return true;
        }
        return false;
      };
      // Before a shrink of a feather turned aside at the frame before (no turn, yaw or bend keeps it
      // clear of the lower vanes and out from under them, and no bend keeps it clear of the vanes at
      // all): turned aside as far as keeping it clear of the lower vanes and the skin only, left under a
      // lower feather (named) rather than shrunk. The
      // yaws nearest `preferred` first (the yaw of the frame before); at that yaw, the turn nearest
      // `preferred_angle` (its turn there: steps of kAsideStep either way, one up, then one down, then
      // bisection toward it), at any other the smallest (smallest_clear_step). Found: the feather ends
      // there, and true; none: false, nothing changed.
      auto aside_left_under = [&](double preferred, double preferred_angle) {
        if (lower.empty()) return false;
        std::array<double, std::size(kAsideYaws)> yaws;
        std::copy(std::begin(kAsideYaws), std::end(kAsideYaws), yaws.begin());
        std::stable_sort(yaws.begin(), yaws.end(),
                         [&](double a, double b) { return std::abs(a - preferred) < std::abs(b - preferred); });
        for (const double yaw : yaws) {
          const auto clears_at = [&](double a) { return clear_aside_only(yaw, a); };
          const double clearing =
              yaw == preferred && preferred_angle >= 0.0
                  ? nearest_clear_step(std::clamp(preferred_angle, 0.0, max_angle), kAsideStep, clears_at)
                  : smallest_clear_step(clears_at);
          if (clearing < 0.0) continue;
          end_aside(yaw, clearing, false);
          return true;
        }
        return false;
      };

      // A feather turned aside at the frame before, at `yaw` and `angle` (docs/feathers.md, "The
      // layering pass's warm start"): where that still clears, its yaw falls back toward none by at
      // most `fall` (the smallest yaw in that range that clears, by bisection to `tolerance`), or,
      // where the yaw cannot fall at all, its turn by at most `fall` (the smallest that clears); where
      // it no longer clears, the nearest turn that does at that yaw, by steps either way (one up,
      // then one down, up to kLocalSteps of them). Found: the feather ends there, and true; none:
      // false, nothing changed. A yaw fallen to 0 ends as a turn about the axis.
      auto keep_aside = [&](double yaw, double angle, double fall, double tolerance) {
        if (lower.empty() || outward.empty()) return false;
        const auto clear_at = [&](double y, double a) { return clear_moved(aside_move(y, a)); };
        const auto clears_at_yaw = [&](double a) { return clear_at(yaw, a); };
        const auto end_kept = [&](double y, double a) {
          if (y != 0.0) {
            end_aside(y, a);
            return;
          }
          if (a > 0.0) turn_by(a);
          if (counted_under) --left_under;
          unordered[i] = 0;
        };
        if (clear_at(yaw, angle)) {
          const double target = std::abs(yaw) <= fall ? 0.0 : yaw - std::copysign(fall, yaw);
          if (clear_at(target, angle)) {
            end_kept(target, angle);
            return true;
          }
          const double clearing = nearest_clear(yaw, target, tolerance, [&](double y) { return clear_at(y, angle); });
          if (clearing != yaw || angle == 0.0) {
            end_kept(clearing, angle);
            return true;
          }
          // The yaw cannot fall: the turn falls instead, among the turns that clear.
          const double below = std::max(angle - fall, 0.0);
          end_kept(yaw, clears_at_yaw(below) ? below : nearest_clear(angle, below, tolerance, clears_at_yaw));
          return true;
        }
        double last_up = angle, last_down = angle;
        for (int s = 1; s <= kLocalSteps && (last_up < max_angle || last_down > 0.0); ++s) {
          const double up = std::min(angle + s * kStep, max_angle), down = std::max(angle - s * kStep, 0.0);
          if (up > last_up) {
            if (clear_at(yaw, up)) {
              end_kept(yaw, nearest_clear(up, last_up, tolerance, clears_at_yaw));
              return true;
            }
            last_up = up;
          }
          if (down < last_down) {
            if (clear_at(yaw, down)) {
              end_kept(yaw, nearest_clear(down, last_down, tolerance, clears_at_yaw));
              return true;
            }
            last_down = down;
          }
        }
        return false;
      };

      // Bent where it must (docs/feathers.md, "Bent"): a feather no turn about its root, nor a yaw,
      // takes out from under the lower ones (or clear of their vanes) is bent along its shaft (Barr's
      // bend: in the feather's frame, shaft u, up w = axis x u toward the skin normal, the part beyond
      // `start` of the shaft's length follows a circular arc about an axis parallel to `axis`, by
      // `bend` radians at the tip, positive up; lengths along the shaft are kept), then turned about
      // its axis. The bends of kBends are tried, the smallest change of shape first (the one of the
      // frame before first, with a warm start), each with the smallest turn (steps of kAsideStep up
      // to the skin normal, then bisection) at which the same exact tests pass; the whole feather
      // (rachis, barbs, vanes) moves by the same map.
      const Vec bend_u = shaft.normalized();
      const Vec bend_w = axis.cross(bend_u).normalized();
      double bend_length = 0.0;  // of the shaft, as far as the vanes reach along it
      for (int64_t x = v0; x < v1; ++x)
        bend_length =
            std::max(bend_length, (r_frame.vanes.positions[size_t(x)].cast<double>() - mine.root).dot(bend_u));
      // Where the bend (from `start` of the shaft's length, by `bend` radians at its end), then the
      // turn by `angle` about the axis, take the point p (world). Curvature k over [from, bend_length]:
      // a point at (along, up) lies at the radius 1/k - up from the arc's center (from, 1/k), turned
      // by k (along - from); beyond the shaft's end the arc goes on (the vanes end there). The tests
      // and the feather's final points use this one map, in double.
      struct BentMap {
        Eigen::Matrix3d turn;
        double from, k;
      };
      const auto bent_map = [&](double angle, double start, double bend) {
        const double from = start * bend_length;
        return BentMap{Eigen::AngleAxisd(angle, axis).toRotationMatrix(), from, bend / (bend_length - from)};
      };
      const auto bent_point = [&](const BentMap &map, const Vec &p) {
        const Vec d = p - mine.root;
        const double along = d.dot(bend_u);
        if (along <= map.from) return Vec(mine.root + map.turn * d);
        const double up = d.dot(bend_w), across = d.dot(axis);
        const double radius = 1.0 / map.k - up, phi = map.k * (along - map.from);
        return Vec(mine.root + map.turn * ((map.from + radius * std::sin(phi)) * bend_u +
                                           (1.0 / map.k - radius * std::cos(phi)) * bend_w + across * axis));
      };
      auto clear_bent = [&](double angle, double start, double bend, bool under_too) {
        const BentMap map = bent_map(angle, start, bend);
        return clear_mapped([&](const Vec &p) { return bent_point(map, p); }, false, under_too);
      };
      auto end_bent = [&](double angle, double start, double bend, bool out) {
        const BentMap map = bent_map(angle, start, bend);
        for (int64_t p = ranges.first_point[i]; p < ranges.first_point[i + 1]; ++p) {
          Eigen::Vector3f &x = r_frame.curves.curves.positions[size_t(p)];
          x = bent_point(map, x.cast<double>()).cast<float>();
        }
        for (int64_t p = ranges.first_vertex[i]; p < ranges.first_vertex[i + 1]; ++p) {
          Eigen::Vector3f &x = r_frame.vanes.positions[size_t(p)];
          x = bent_point(map, x.cast<double>()).cast<float>();
        }
        record_turn(angle);
        ++bent;
        if (r_state) {
          r_state->bends[i] = float(bend);
          r_state->bend_starts[i] = float(start);
        }
        end_out(out);
      };
      // The bends tried (start, bend), nearest the preferred one first (the frame before's; a bend of 0:
      // the order of kBends).
      auto bends_nearest = [&](double preferred_start, double preferred_bend) {
        std::array<std::pair<double, double>, std::size(kBends)> bends;
        std::copy(std::begin(kBends), std::end(kBends), bends.begin());
        if (preferred_bend != 0.0)
          std::stable_sort(bends.begin(), bends.end(), [&](const auto &a, const auto &b) {
            return std::abs(a.first - preferred_start) + std::abs(a.second - preferred_bend) <
                   std::abs(b.first - preferred_start) + std::abs(b.second - preferred_bend);
          });
        return bends;
      };
      // Before a shrink (no turn or yaw keeps it clear of the lower vanes): the bends tried, the
      // smallest change of shape ((1 - start) |bend|) first, or nearest the preferred one (the frame
      // before's) first, each at the smallest turn that keeps it clear of the lower vanes and the skin
      // (steps of kAsideStep, then bisection); the first out from under every lower feather there is
      // taken, else the first found (left under). None: false, nothing changed.
      auto bend_clear = [&](double preferred_start, double preferred_bend) {
        if (lower.empty() || !(bend_length > 0.0)) return false;
        const auto bends = bends_nearest(preferred_start, preferred_bend);
        double kept_angle = -1.0, kept_start = 0.0, kept_bend = 0.0;
        for (const auto &[start, bend] : bends) {
          const double clearing = smallest_clear_step([&](double a) { return clear_bent(a, start, bend, false); });
          if (clearing < 0.0) continue;
          if (outward.empty() || clear_bent(clearing, start, bend, true)) {
            end_bent(clearing, start, bend, true);
            return true;
          }
          if (kept_angle < 0.0) {
            kept_angle = clearing;
            kept_start = start;
            kept_bend = bend;
          }
        }
        if (kept_angle < 0.0) return false;
        end_bent(kept_angle, kept_start, kept_bend, false);
        return true;
      };
      // Left under: of the bends, each at the 2 kLocalSteps + 1 turns by steps of kAsideStep about
      // `near` (the turn under the fewest; from no turn where it is lower) that keep it clear of the
      // lower vanes and the skin, the one under the fewest lower feathers, when fewer than `best`
      // (that turn's): the feather ends there (left under, or out when under none), and true. With a
      // warm start, the bend and turn of the frame before (`preferred_angle`) compete too, first: the
      // feather stays there when that is under no more than `best`, unless another bend is under
      // fewer.
      auto bend_fewest = [&](double preferred_start, double preferred_bend, double preferred_angle, double near,
                             std::ptrdiff_t best) {
        if (lower.empty() || outward.empty() || !(bend_length > 0.0)) return false;
        const auto bends = bends_nearest(preferred_start, preferred_bend);
        double best_angle = -1.0, best_start = 0.0, best_bend = 0.0;
        if (preferred_bend != 0.0 && preferred_angle >= 0.0 &&
            clear_bent(preferred_angle, preferred_start, preferred_bend, false)) {
          const std::ptrdiff_t count = count_moved(best + 1);
          if (count <= best) {
            best = count;
            best_angle = preferred_angle;
            best_start = preferred_start;
            best_bend = preferred_bend;
          }
        }
        const double lowest = std::max(near - kLocalSteps * kAsideStep, 0.0);
        for (const auto &[start, bend] : bends) {
          for (int s = 0; s <= 2 * kLocalSteps && best > 0; ++s) {
            const double at = std::min(lowest + s * kAsideStep, max_angle);
            if (s > 0 && at == std::min(lowest + (s - 1) * kAsideStep, max_angle)) break;
            if (!clear_bent(at, start, bend, false)) continue;
            const std::ptrdiff_t count = count_moved(best);
            if (count < best) {
              best = count;
              best_angle = at;
              best_start = start;
              best_bend = bend;
            }
          }
        }
        if (best_angle < 0.0) return false;
        end_bent(best_angle, best_start, best_bend, best == 0);
        return true;
      };
      // A feather bent at the frame before: where its bend and turn still clear, the bend falls back
      // toward none by at most `fall` (where that clears), the turn kept. Found: true; else false,
      // nothing changed.
      auto keep_bent = [&](double angle, double start, double bend, double fall) {
        if (lower.empty() || !(bend_length > 0.0) || !clear_bent(angle, start, bend, !outward.empty())) return false;
        const double target = std::abs(bend) <= fall ? 0.0 : bend - std::copysign(fall, bend);
        if (target == 0.0) {
          if (!conflict(angle)) {
            if (angle > 0.0) turn_by(angle);
            return true;
          }
        } else if (clear_bent(angle, start, target, !outward.empty())) {
          end_bent(angle, start, target, true);
          return true;
        }
        end_bent(angle, start, bend, true);
        return true;
      };

      // The warm start (docs/feathers.md, "The layering pass's warm start"): from the turn and size
      // the feather had at the frame before.
      double from = -1.0;     // the turn at the frame before, with a warm start
      // The yaw at the frame before (0: not turned aside): turning aside afresh tries the yaws nearest
      // it first.
      double previous_yaw = 0.0;
      // The bend at the frame before (0: not bent) and where it started: bending afresh tries the
      // bends nearest it first.
      double previous_bend = 0.0, previous_bend_start = 0.0;
      bool searched = false;  // whether the warm start tried every step of the range and none cleared
      if (previous) {
        // How far the turn may fall back per frame: its vanes' farthest point by fall_back rachis widths.
        const double fall = double(options.fall_back) * double(warm.rachis_widths[i]) * double(r_frame.scales[i]) /
                            std::max(mine.extent, 1e-300);
        const double previous_size = double(previous->scales[i]);
        // The warm start's bisections stop at a sixteenth of that step (1/64 rachis width at the farthest
        // point), not at 1e-4 radians: finer moves nothing a frame can see, and took 40% of the pass.
        const double tolerance = std::max(1e-4, fall / 16.0);
        if (previous_size < 1.0 && previous_size + fall < 1.0) {
          // Shrunk at the frame before: unturned, it grows back by at most `fall` of its size, as far as
          // it clears; where its size of the frame before no longer clears, the largest that does below
          // it. (Whether a size clears is not monotone in the size: a bisection over [0, cap] may land
          // far below a size that clears.)
          const double cap = previous_size + fall;
          gather(false);
          witness = {};
          // As the search's shrink (which comes after no turn took it out from under the lower
          // feathers): kept clear of their vanes and the skin, not out from under them.
          if (under_test) {
            under_test = false;
            ++left_under;
          }
          double size = cap;
          if (conflict(0.0, cap)) {
            // The nearest size that clears at or below the one of the frame before: down by steps of
            // `fall` (up to kShrinkSteps of them), then bisection between the last two.
            double above = cap, at = previous_size;
            int k = 0;
            while (k < kShrinkSteps && at > 0.0 && conflict(0.0, at)) {
              above = at;
              at = std::max(previous_size - double(++k) * fall, 0.0);
            }
            if (k < kShrinkSteps && !conflict(0.0, at)) {
              for (int b = 0; b < 12; ++b) {
                const double mid = 0.5 * (at + above);
                (conflict(0.0, mid) ? above : at) = mid;
              }
              size = at;
            } else {
              size = largest_clear_size(at);
            }
          }
          shrink_to(size);
          continue;
        }
        previous_yaw = previous->yaws.empty() ? 0.0 : double(previous->yaws[i]);
        from = std::clamp(double(previous->turns[i]), 0.0, max_angle);
        if (!previous->bends.empty() && previous->bends[i] != 0.0f) {
          previous_bend = double(previous->bends[i]);
          previous_bend_start = double(previous->bend_starts[i]);
          if (keep_bent(from, previous_bend_start, previous_bend, fall)) continue;
        }
        if (from > 0.0) {
          if (!conflict(from)) {
            // Still clear: down toward the template by at most `fall`, without leaving the turns that clear.
            const double target = std::max(from - fall, 0.0);
            end_at(!conflict(target) ? target : lowest_clear(target, from, tolerance));
            continue;
          }
          // Pushed out: the nearest turn that clears, by steps either way (one up, then one down), up to
          // kLocalSteps of them; above it the smallest such turn, below it the largest. Where the steps
          // reach both ends of the range and none clears, no turn does.
          bool found = false;
          double last_up = from, last_down = from;
          for (int s = 1; s <= kLocalSteps && !found && (last_up < max_angle || last_down > 0.0); ++s) {
            const double up = std::min(from + s * kStep, max_angle), down = std::max(from - s * kStep, 0.0);
            if (up > last_up) {
              if (!conflict(up)) {
                end_at(lowest_clear(last_up, up, tolerance));
                found = true;
                break;
              }
              last_up = up;
            }
            if (down < last_down) {
              if (!conflict(down)) {
                end_at(highest_clear(down, last_down, tolerance));
                found = true;
                break;
              }
              last_down = down;
            }
          }
          searched = last_up >= max_angle && last_down <= 0.0;
          if (found) continue;
        }
        // Turned aside at the frame before, and its turn about the axis, or one near it, no longer
        // clears: its yaw is kept where it can be, before the search from no turn (which may lift it
        // far).
        if (previous_yaw != 0.0 && (from > 0.0 || conflict(0.0)) && keep_aside(previous_yaw, from, fall, tolerance))
          continue;
      }

      // The full search: the smallest turn that clears, by steps from no turn, then bisection. Per step
      // (0 unturned), what is known of it without the test for lower feathers over it (as conflict's
      // r_clear; -1 unknown): the search for the turn under the fewest reuses it.
      std::vector<signed char> step_clear(1, -1);
      if (!searched && !conflict(0.0, 1.0, &step_clear[0])) continue;
      double below = 0.0, above = -1.0;
      for (double a = kStep; !searched && a < max_angle + kStep; a += kStep) {
        const double at = std::min(a, max_angle);
        step_clear.push_back(-1);
        if (!conflict(at, 1.0, &step_clear.back())) {
          above = at;
          break;
        }
        below = at;
      }
      if (above < 0.0 && under_test) {
        // No turn up to the skin normal takes it out from under the lower feathers: it is left under
        // some (named), rather than shrunk until none is over it. Of the turns that keep it clear of
        // them (the steps up to the normal), the lowest under the fewest lower feathers is taken,
        // then lowered (bisection) as far as it stays under no more.
        under_test = false;
        witness = {};
        ++left_under;
        counted_under = true;
        unordered[i] = 1;
        // With a warm start, the turn of the frame before competes too, when it keeps it clear of the
        // lower feathers' vanes and the skin: it stays there unless a step within kLocalSteps of it is
        // under fewer (a step farther away would be a jump).
        // So does a feather's yaw and turn of the frame before, where it was turned aside (or left
        // under at a yaw): it stays at that yaw unless a step near its turn is under fewer.
        std::ptrdiff_t best = PTRDIFF_MAX;
        // At that yaw, its turn, or the nearest that keeps it clear, by steps either way over the whole
        // range (within kLocalSteps only, a feather turned aside whose turn closed at its yaw took the
        // turn under the fewest about the unturned axis, up to a radian away).
        const double aside_at =
            previous_yaw != 0.0 && from >= 0.0
                ? nearest_clear_step(from, kStep, [&](double a) { return clear_aside_only(previous_yaw, a); })
                : -1.0;
        // (A turn the search returns clears; the test runs again at it so that count_moved counts the
        // vertices as placed there, not at the last turn the search tried.)
        const bool stay_aside = aside_at >= 0.0 && clear_aside_only(previous_yaw, aside_at);
        const bool stay = !stay_aside && from >= 0.0 && !conflict(from);
        if (stay_aside) best = count_moved(PTRDIFF_MAX);
        if (stay) {
          best = under_count(from, PTRDIFF_MAX);
          above = from;
        }
        auto worse = [&](double angle, std::ptrdiff_t bound) {
          return conflict(angle) || under_count(angle, bound + 1) > bound;
        };
        double previous_step = 0.0, best_below = 0.0;
        size_t step = 0;
        for (double a = 0.0; a < max_angle + kStep; a += kStep, ++step) {
          const double at = std::min(a, max_angle);
          const signed char known_clear = step < step_clear.size() ? step_clear[step] : -1;
          const bool near = !(stay || stay_aside) || std::abs(at - from) <= kLocalSteps * kStep;
          if (near && (known_clear == 1 || (known_clear == -1 && !conflict(at)))) {
            const std::ptrdiff_t count = under_count(at, best);
            if (count < best) {
              best = count;
              above = at;
              best_below = previous_step;
            }
          }
          previous_step = at;
          // Every turn clear of the lower feathers is under one at least (the search above found no
          // turn under none): the first under one only is the answer.
          if (at == max_angle || best <= 1) break;
        }
        if (stay && above == from) {
          if (!turn_aside(previous_yaw) && !bend_fewest(previous_bend_start, previous_bend, from, from, best))
            end_at(from);
          continue;
        }
        if (stay_aside && above < 0.0) {
          if (!turn_aside(previous_yaw) && !bend_fewest(previous_bend_start, previous_bend, from, from, best))
            end_aside(previous_yaw, aside_at, best == 0);
          continue;
        }
        if (above > 0.0) {
          below = best_below;
          while (above - below > 1e-4) {
            const double mid = 0.5 * (below + above);
            (worse(mid, best) ? below : above) = mid;
          }
        }
        if (above >= 0.0 &&
            (turn_aside(previous_yaw) || bend_fewest(previous_bend_start, previous_bend, from, above, best)))
          continue;
      }
      if (above < 0.0) {
        // No turn clears it (lower feathers stand over its root): turned aside where that clears it,
        // else bent (out from under the lower feathers where a bend takes it out, else clear of their
        // vanes only: left under rather than shrunk), else, where it was turned aside at the frame
        // before, turned aside clear of their vanes only (left under: it keeps its yaw rather than
        // collapse), else, unturned, it is shrunk toward its root until it clears (the largest such
        // size), as the skin pass does. (Turning aside so every feather that would be shrunk, yawed or
        // not, left 4 in 10 fewer shrunk on the 2,000-feather proxy, but 12% more layer-order
        // violations and twice the order flips: a feather kept whole crowds the ones above it.)
        if (turn_aside(previous_yaw) || bend_clear(previous_bend_start, previous_bend) ||
            (previous_yaw != 0.0 && aside_left_under(previous_yaw, from)))
          continue;
        shrink_to(largest_clear_size(1.0));
        continue;
      }
      if (above == 0.0) continue;
      turn_by(lowest_clear(below, above));
    }
    {
      const std::lock_guard<std::mutex> lock(mutex);
      for (const int32_t k : higher[i])
        if (--waiting[size_t(k)] == 0) ready.push(k);
      ++done;
    }
    woken.notify_all();
  }
  stats.lifted = lifted;
  stats.unresolved = unresolved;
  stats.left_under = left_under;
  stats.turned_aside = aside_count;
  stats.bent = bent;
  for (size_t i = 0; i < n; ++i)
    if (unordered[i]) stats.unordered.push_back(int32_t(i));
  stats.largest_lift = largest;
  return stats;
}

}  // namespace plume::feathers
