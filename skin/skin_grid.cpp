#include "skin/skin_grid.h"

#include <algorithm>
#include <cmath>

namespace plume::skin {

namespace {

/// Two distances within this factor are a near tie (see SkinGrid::signed_at).
constexpr float kNearTie = 1.0001f;

}  // namespace

SkinGrid::SkinGrid(const Mesh &mesh, const MeshQuery &query) : mesh_(mesh), query_(query) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  double edge_sum = 0.0;
  size_t used = 0;
  // Triangles without area (degenerate) are left out of the grid.
  std::vector<uint8_t> listed_triangle(mesh.triangle_count());
  for (size_t f = 0; f < mesh.triangle_count(); ++f) listed_triangle[f] = mesh.triangle_area(f) > 0.0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    if (!listed_triangle[f]) continue;
    const Eigen::Vector3i &t = mesh.triangles[f];
    for (int i = 0; i < 3; ++i) {
      lo = lo.cwiseMin(mesh.positions[size_t(t[i])]);
      hi = hi.cwiseMax(mesh.positions[size_t(t[i])]);
      edge_sum += (mesh.positions[size_t(t[i])] - mesh.positions[size_t(t[(i + 1) % 3])]).norm();
    }
    ++used;
  }
  dims_ = Eigen::Vector3i::Ones();
  origin_ = lo;
  box_high_ = hi;
  if (used == 0) return;
  // Cells of about two mean edges, at most 128 per axis.
  const Eigen::Vector3f extent = (hi - lo).cwiseMax(1e-12f);
  cell_size_ = std::max({float(2.0 * edge_sum / double(3 * used)), extent.maxCoeff() / 128.0f, 1e-12f});
  for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(int(std::ceil(extent[a] / cell_size_)), 1, 128);
  const size_t cell_count = size_t(dims_.x()) * size_t(dims_.y()) * size_t(dims_.z());
  // The cells: each triangle listed in the cells it touches, and each cell's distance to the nearest
  // listed one.
  auto cell_range = [&](size_t f, Eigen::Vector3i &r_lo, Eigen::Vector3i &r_hi) {
    const Eigen::Vector3i &t = mesh.triangles[f];
    Eigen::Vector3f tlo = mesh.positions[size_t(t[0])], thi = tlo;
    for (int i = 1; i < 3; ++i) {
      tlo = tlo.cwiseMin(mesh.positions[size_t(t[i])]);
      thi = thi.cwiseMax(mesh.positions[size_t(t[i])]);
    }
    for (int a = 0; a < 3; ++a) {
      r_lo[a] = std::clamp(int(std::floor((tlo[a] - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
      r_hi[a] = std::clamp(int(std::floor((thi[a] - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
    }
  };
  cell_offsets_.assign(cell_count + 1, 0);
  // Each triangle's bounding disc, listed in every cell its bounding box touches; then packed four
  // to a block, cell by cell.
  struct Listed {
    Eigen::Vector3f centre, normal;
    float radius;
    int32_t triangle;
  };
  auto bounding_disc = [&](size_t f) {
    const Eigen::Vector3f centre = (vertex(int(f), 0) + vertex(int(f), 1) + vertex(int(f), 2)) / 3.0f;
    float radius_sq = 0.0f;
    for (int i = 0; i < 3; ++i) radius_sq = std::max(radius_sq, (vertex(int(f), i) - centre).squaredNorm());
    const Eigen::Vector3f normal =
        (vertex(int(f), 1) - vertex(int(f), 0)).cross(vertex(int(f), 2) - vertex(int(f), 0));
    const float norm = normal.norm();
    // A triangle too thin for a normal gets none: the disc test is then the sphere test.
    return Listed{centre, norm > 0.0f ? Eigen::Vector3f(normal / norm) : Eigen::Vector3f::Zero(),
                  std::sqrt(radius_sq), int32_t(f)};
  };
  std::vector<int32_t> listed_offsets(cell_count + 1, 0);
  std::vector<Listed> listed;
  Eigen::Vector3i clo, chi;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int32_t> fill;
    if (pass == 1) {
      for (size_t c = 0; c < cell_count; ++c) listed_offsets[c + 1] += listed_offsets[c];
      listed.resize(size_t(listed_offsets[cell_count]));
      fill.assign(listed_offsets.begin(), listed_offsets.end() - 1);
    }
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
      if (!listed_triangle[f]) continue;
      cell_range(f, clo, chi);
      for (int z = clo.z(); z <= chi.z(); ++z)
        for (int y = clo.y(); y <= chi.y(); ++y)
          for (int x = clo.x(); x <= chi.x(); ++x) {
            const size_t c = cell_index(x, y, z);
            if (pass == 0)
              ++listed_offsets[c + 1];
            else
              listed[size_t(fill[c]++)] = bounding_disc(f);
          }
    }
  }
  for (size_t c = 0; c < cell_count; ++c)
    cell_offsets_[c + 1] = cell_offsets_[c] + (listed_offsets[c + 1] - listed_offsets[c] + 3) / 4;
  CellBlock padding;
  for (int a = 0; a < 3; ++a) {
    padding.centre[a] = Float4{} + INFINITY;  // never within reach
    padding.normal[a] = Float4{};
  }
  padding.radius = Float4{};
  padding.triangle = Int4{} - 1;
  cell_blocks_.assign(size_t(cell_offsets_[cell_count]), padding);
  for (size_t c = 0; c < cell_count; ++c)
    for (int32_t i = listed_offsets[c]; i < listed_offsets[c + 1]; ++i) {
      const Listed &entry = listed[size_t(i)];
      CellBlock &block = cell_blocks_[size_t(cell_offsets_[c] + (i - listed_offsets[c]) / 4)];
      const int lane = (i - listed_offsets[c]) % 4;
      for (int a = 0; a < 3; ++a) {
        block.centre[a][lane] = entry.centre[a];
        block.normal[a][lane] = entry.normal[a];
      }
      block.radius[lane] = entry.radius;
      block.triangle[lane] = entry.triangle;
    }
  // Chessboard distance transform: two raster passes over the 26-neighbourhood are exact for it. They
  // run on a copy padded by one cell of 255 on every side, so that no neighbour needs a bounds test.
  const int64_t padded_x = dims_.x() + 2, padded_y = dims_.y() + 2, padded_z = dims_.z() + 2;
  std::vector<uint8_t> padded(size_t(padded_x * padded_y * padded_z), 255);
  auto padded_index = [&](int x, int y, int z) {
    return size_t((int64_t(z + 1) * padded_y + (y + 1)) * padded_x + (x + 1));
  };
  for (int z = 0; z < dims_.z(); ++z)
    for (int y = 0; y < dims_.y(); ++y)
      for (int x = 0; x < dims_.x(); ++x) {
        const size_t c = cell_index(x, y, z);
        if (cell_offsets_[c + 1] > cell_offsets_[c]) padded[padded_index(x, y, z)] = 0;
      }
  // The 13 neighbours a forward raster has already visited: the whole layer below, the row before,
  // the cell before.
  int64_t before[13];
  int count = 0;
  for (int dz = -1; dz <= 0; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dz < 0 || dy < 0 || (dy == 0 && dx < 0)) before[count++] = (dz * padded_y + dy) * padded_x + dx;
  for (int pass = 0; pass < 2; ++pass) {
    const int64_t sign = pass == 0 ? 1 : -1;
    for (int zi = 0; zi < dims_.z(); ++zi)
      for (int yi = 0; yi < dims_.y(); ++yi)
        for (int xi = 0; xi < dims_.x(); ++xi) {
          const int z = pass == 0 ? zi : dims_.z() - 1 - zi, y = pass == 0 ? yi : dims_.y() - 1 - yi,
                    x = pass == 0 ? xi : dims_.x() - 1 - xi;
          uint8_t *cell = padded.data() + padded_index(x, y, z);
          int best = *cell;
          for (int n = 0; n < 13; ++n) best = std::min(best, int(cell[sign * before[n]]) + 1);
          *cell = uint8_t(std::min(best, 255));
        }
  }
  cell_distance_.resize(cell_count);
  for (int z = 0; z < dims_.z(); ++z)
    for (int y = 0; y < dims_.y(); ++y)
      for (int x = 0; x < dims_.x(); ++x) cell_distance_[cell_index(x, y, z)] = padded[padded_index(x, y, z)];
  // The cells an open edge of the mesh (MeshQuery::open_edges) passes through, by its bounding box,
  // and one cell around.
  for (const auto &[low, high] : query.open_edges()) {
    if (near_open_edge_.empty()) near_open_edge_.assign(cell_count, 0);
    const Eigen::Vector3f &a = mesh.positions[low], &b = mesh.positions[high];
    Eigen::Vector3i first_cell, last_cell;
    for (int axis = 0; axis < 3; ++axis) {
      const int low_cell = int(std::floor((std::min(a[axis], b[axis]) - origin_[axis]) / cell_size_));
      const int high_cell = int(std::floor((std::max(a[axis], b[axis]) - origin_[axis]) / cell_size_));
      first_cell[axis] = std::clamp(low_cell - 1, 0, dims_[axis] - 1);
      last_cell[axis] = std::clamp(high_cell + 1, 0, dims_[axis] - 1);
    }
    for (int z = first_cell.z(); z <= last_cell.z(); ++z)
      for (int y = first_cell.y(); y <= last_cell.y(); ++y)
        for (int x = first_cell.x(); x <= last_cell.x(); ++x) near_open_edge_[cell_index(x, y, z)] = 1;
  }
}

float SkinGrid::distance_lower_bound(const Eigen::Vector3f &p) const {
  if (cell_distance_.empty()) return 0.0f;
  const Eigen::Vector3i c = cell_of(p);
  const int k = cell_distance_[cell_index(c.x(), c.y(), c.z())];
  const float cells = float(std::max(k - 1, 0)) * cell_size_;
  const float outside_sq = (origin_ - p).cwiseMax(p - box_high_).cwiseMax(0.0f).squaredNorm();
  return outside_sq > cells * cells ? std::sqrt(outside_sq) : cells;
}

float SkinGrid::block_lower_bound(const Eigen::Vector3f &p) const {
  if (cell_blocks_.empty()) return 0.0f;
  Eigen::Vector3i lo, hi, own;
  // gap_sq[a][d + 1]: squared distance along axis a from p to the slab of the cell at offset d from
  // p's own cell, so that the squared distance to the box of neighbour (dx, dy, dz) is the sum of
  // three table entries. p may lie outside the grid (its cell clamped).
  float gap_sq[3][3];
  float bound_sq = INFINITY;
  for (int a = 0; a < 3; ++a) {
    const float local = (p[a] - origin_[a]) / cell_size_;
    const int cell = std::clamp(int(std::floor(local)), 0, dims_[a] - 1);
    own[a] = cell;
    lo[a] = std::max(cell - 1, 0);
    hi[a] = std::min(cell + 1, dims_[a] - 1);
    const float below = std::max(local - float(cell), 0.0f) * cell_size_;
    const float inside = std::max({float(cell) - local, local - float(cell + 1), 0.0f}) * cell_size_;
    const float above = std::max(float(cell + 1) - local, 0.0f) * cell_size_;
    gap_sq[a][0] = below * below;
    gap_sq[a][1] = inside * inside;
    gap_sq[a][2] = above * above;
    // Cells outside the grid hold no triangle; inside it, the block's faces bound the rest.
    if (lo[a] > 0) {
      const float gap = std::max(local - float(lo[a]), 0.0f) * cell_size_;
      bound_sq = std::min(bound_sq, gap * gap);
    }
    if (hi[a] < dims_[a] - 1) {
      const float gap = std::max(float(hi[a] + 1) - local, 0.0f) * cell_size_;
      bound_sq = std::min(bound_sq, gap * gap);
    }
  }
  const size_t own_cell = cell_index(own.x(), own.y(), own.z());
  // When p's own cell holds a triangle, its box is the nearest of all boxes; when no cell within
  // one holds one (chessboard distance 2 or more), only the block's faces bound.
  if (cell_offsets_[own_cell] != cell_offsets_[own_cell + 1])
    return std::sqrt(gap_sq[0][1] + gap_sq[1][1] + gap_sq[2][1]);
  if (cell_distance_[own_cell] >= 2) return std::sqrt(bound_sq);
  const int64_t stride_y = dims_.x(), stride_z = int64_t(dims_.x()) * dims_.y();
  for (int dz = lo.z() - own.z(); dz <= hi.z() - own.z(); ++dz)
    for (int dy = lo.y() - own.y(); dy <= hi.y() - own.y(); ++dy) {
      const float yz_sq = gap_sq[1][dy + 1] + gap_sq[2][dz + 1];
      const int64_t row = int64_t(own_cell) + dz * stride_z + dy * stride_y;
      for (int dx = lo.x() - own.x(); dx <= hi.x() - own.x(); ++dx) {
        const size_t c = size_t(row + dx);
        if (cell_offsets_[c] != cell_offsets_[c + 1]) bound_sq = std::min(bound_sq, gap_sq[0][dx + 1] + yz_sq);
      }
    }
  return std::sqrt(bound_sq);
}

float SkinGrid::signed_at(const Eigen::Vector3f &p, const Nearest &nearest, SurfacePoint &r_closest) const {
  r_closest.triangle = nearest.best;
  r_closest.bary = nearest.best_bary;
  const float distance = std::sqrt(nearest.best_sq);
  const Eigen::Vector3f offset = p - surface_position(mesh_, r_closest);
  const float side = offset.dot(query_.side_normal(r_closest));
  bool ill_conditioned = std::abs(side) < 0.05f * offset.norm();
  if (!ill_conditioned && nearest.second >= 0 && nearest.second_sq <= nearest.best_sq * kNearTie * kNearTie) {
    const SurfacePoint runner_up{nearest.second, nearest.second_bary};
    const float other_side = (p - surface_position(mesh_, runner_up)).dot(query_.side_normal(runner_up));
    ill_conditioned = (other_side < 0.0f) != (side < 0.0f);
  }
  if (ill_conditioned) return query_.signed_distance(p, &r_closest);
  return side < 0.0f ? -distance : distance;
}

bool SkinGrid::hint_distance(const Eigen::Vector3f &p, int hint, Eigen::Vector3f &r_bary, float &r_distance_sq) const {
  if (hint < 0 || size_t(hint) >= mesh_.triangle_count() || cell_blocks_.empty()) return false;
  r_bary = closest_on_triangle(p, vertex(hint, 0), vertex(hint, 1), vertex(hint, 2));
  r_distance_sq = (p - (r_bary[0] * vertex(hint, 0) + r_bary[1] * vertex(hint, 1) + r_bary[2] * vertex(hint, 2)))
                      .squaredNorm();
  // A degenerate triangle (not in the grid) gives no usable distance.
  return r_bary.allFinite() && std::isfinite(r_distance_sq);
}

inline int SkinGrid::may_be_within(const CellBlock &block, Float4 px, Float4 py, Float4 pz, float reach) {
  const Float4 ox = px - block.centre[0], oy = py - block.centre[1], oz = pz - block.centre[2];
  const Float4 offset_sq = ox * ox + oy * oy + oz * oz;
  const Float4 far = block.radius + reach;
  const Float4 height = ox * block.normal[0] + oy * block.normal[1] + oz * block.normal[2];
  const Float4 slack = 1e-6f * offset_sq;  // about ten roundings of the squares below
  const Float4 height_sq = height * height - slack;
  const Float4 beside_sq = offset_sq - height * height - slack;
  const Float4 beside = lane_sqrt(beside_sq > 0.0f ? beside_sq : Float4{}) - block.radius;
  const Float4 lower_sq = (height_sq > 0.0f ? height_sq : Float4{}) + (beside > 0.0f ? beside * beside : Float4{});
  // Comparisons with a padding lane's infinite offsets are false (NaN) or reject it.
  return lane_bits(~(offset_sq > far * far) & (lower_sq <= reach * reach) & (block.triangle >= 0));
}

void SkinGrid::closest_in_block(const CellBlock &cell_block, Float4 px, Float4 py, Float4 pz, Float4 r_bary[3],
                                Float4 &r_distance_sq) const {
  struct {
    Float4 corner[3][3];
  } block;
  for (int l = 0; l < 4; ++l) {
    const int f = std::max(cell_block.triangle[l], 0);
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) block.corner[i][a][l] = vertex(f, i)[a];
  }
  // closest_on_triangle's operations lane by lane, every region's answer computed and the first
  // whose condition holds kept, in the order of its tests (dot products add x + (y + z), as Eigen).
  const Float4 p[3] = {px, py, pz};
  Float4 ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int a = 0; a < 3; ++a) {
    ab[a] = block.corner[1][a] - block.corner[0][a];
    ac[a] = block.corner[2][a] - block.corner[0][a];
    ap[a] = p[a] - block.corner[0][a];
    bp[a] = p[a] - block.corner[1][a];
    cp[a] = p[a] - block.corner[2][a];
  }
  const Float4 d1 = dot_lanes(ab, ap), d2 = dot_lanes(ac, ap), d3 = dot_lanes(ab, bp), d4 = dot_lanes(ac, bp),
               d5 = dot_lanes(ab, cp), d6 = dot_lanes(ac, cp);
  const Float4 vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  const Float4 zero{}, one = zero + 1.0f;
  // Inside the face (the last case), then each earlier case over it, from the last test back.
  const Float4 denom = 1.0f / (va + vb + vc);
  Float4 v = vb * denom, w = vc * denom;
  Float4 u = 1.0f - v - w;
  auto take = [&](Int4 mask, Float4 mu, Float4 mv, Float4 mw) {
    u = mask ? mu : u;
    v = mask ? mv : v;
    w = mask ? mw : w;
  };
  const Float4 e43 = d4 - d3, e56 = d5 - d6;
  const Float4 w_bc = e43 / (e43 + e56);
  take((va <= 0.0f) & (e43 >= 0.0f) & (e56 >= 0.0f), zero, 1.0f - w_bc, w_bc);
  const Float4 w_ac = d2 / (d2 - d6);
  take((vb <= 0.0f) & (d2 >= 0.0f) & (d6 <= 0.0f), 1.0f - w_ac, zero, w_ac);
  take((d6 >= 0.0f) & (d5 <= d6), zero, zero, one);
  const Float4 v_ab = d1 / (d1 - d3);
  take((vc <= 0.0f) & (d1 >= 0.0f) & (d3 <= 0.0f), 1.0f - v_ab, v_ab, zero);
  take((d3 >= 0.0f) & (d4 <= d3), zero, one, zero);
  take((d1 <= 0.0f) & (d2 <= 0.0f), one, zero, zero);
  r_bary[0] = u;
  r_bary[1] = v;
  r_bary[2] = w;
  Float4 offset[3];
  for (int a = 0; a < 3; ++a)
    offset[a] = p[a] - ((u * block.corner[0][a] + v * block.corner[1][a]) + w * block.corner[2][a]);
  r_distance_sq = dot_lanes(offset, offset);
}

template <class Visit>
bool SkinGrid::visit_near(size_t c, Float4 px, Float4 py, Float4 pz, const float &reach, Visit &&visit) const {
  for (int32_t b = cell_offsets_[c]; b < cell_offsets_[c + 1]; ++b) {
    const CellBlock &block = cell_blocks_[size_t(b)];
    const int lanes = may_be_within(block, px, py, pz, reach);
    if (lanes == 0) continue;
    Float4 bary[3], distance_sq;
    closest_in_block(block, px, py, pz, bary, distance_sq);
    for (int l = 0; l < 4; ++l)
      if ((lanes >> l & 1) && !visit(int(block.triangle[l]), bary, l, distance_sq[l])) return false;
  }
  return true;
}

bool SkinGrid::clear_within(const Eigen::Vector3f &p, float radius) const {
  if (cell_blocks_.empty()) return true;
  Eigen::Vector3i lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(int(std::floor((p[a] - radius - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
    hi[a] = std::clamp(int(std::floor((p[a] + radius - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
  }
  const Eigen::Vector3i span = hi - lo + Eigen::Vector3i::Ones();
  if (span.x() * span.y() * span.z() > 27) return false;
  const float radius_sq = radius * radius;
  const Float4 px = Float4{} + p.x(), py = Float4{} + p.y(), pz = Float4{} + p.z();
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const size_t c = cell_index(x, y, z);
        if (cell_offsets_[c] == cell_offsets_[c + 1] || cell_box_distance_sq(p, x, y, z) >= radius_sq) continue;
        const bool clear = visit_near(c, px, py, pz, radius, [&](int, const Float4 *, int, float distance_sq) {
          return !(distance_sq < radius_sq);
        });
        if (!clear) return false;
      }
  return true;
}

void SkinGrid::scan_cell(const Eigen::Vector3f &p, size_t c, Nearest &r_nearest) const {
  // A triangle whose bounding disc is farther than the best distance (with the near-tie slack) can
  // be neither closer nor a near tie. A block's lanes are tested with the reach at its start; a lane
  // let through by a reach that shrank meanwhile changes nothing.
  float reach = std::sqrt(r_nearest.best_sq) * kNearTie;
  const Float4 px = Float4{} + p.x(), py = Float4{} + p.y(), pz = Float4{} + p.z();
  visit_near(c, px, py, pz, reach, [&](int f, const Float4 *barys, int l, float distance_sq) {
    if (f == r_nearest.best || f == r_nearest.second) return true;  // listed in several cells
    const Eigen::Vector3f bary(barys[0][l], barys[1][l], barys[2][l]);
    if (distance_sq < r_nearest.best_sq || (distance_sq == r_nearest.best_sq && f < r_nearest.best)) {
      r_nearest.second_sq = r_nearest.best_sq;
      r_nearest.second = r_nearest.best;
      r_nearest.second_bary = r_nearest.best_bary;
      r_nearest.best_sq = distance_sq;
      r_nearest.best = f;
      r_nearest.best_bary = bary;
      reach = std::sqrt(distance_sq) * kNearTie;
    } else if (distance_sq < r_nearest.second_sq) {
      r_nearest.second_sq = distance_sq;
      r_nearest.second = f;
      r_nearest.second_bary = bary;
    }
    return true;
  });
}

float SkinGrid::signed_distance(const Eigen::Vector3f &p, int hint, SurfacePoint &r_closest) const {
  Nearest nearest;
  if (!hint_distance(p, hint, nearest.best_bary, nearest.best_sq)) return query_.signed_distance(p, &r_closest);
  nearest.best = hint;
  const float radius = std::sqrt(nearest.best_sq) * kNearTie;
  Eigen::Vector3i lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(int(std::floor((p[a] - radius - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
    hi[a] = std::clamp(int(std::floor((p[a] + radius - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
  }
  const Eigen::Vector3i span = hi - lo + Eigen::Vector3i::Ones();
  if (span.x() * span.y() * span.z() > 27) return query_.signed_distance(p, &r_closest);
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x) scan_cell(p, cell_index(x, y, z), nearest);
  return signed_at(p, nearest, r_closest);
}

bool SkinGrid::local_signed_distance(const Eigen::Vector3f &p, int hint, float &r_distance,
                                     SurfacePoint &r_closest) const {
  Nearest nearest;
  if (!hint_distance(p, hint, nearest.best_bary, nearest.best_sq)) {
    r_distance = query_.signed_distance(p, &r_closest);
    return true;
  }
  nearest.best = hint;
  const float radius = std::sqrt(nearest.best_sq) * kNearTie;
  // The ball of the hint's distance, clipped to the cells next to p's cell. `gap`: how far p is from
  // the faces where the clip cut the ball; triangles beyond them are at least that far.
  Eigen::Vector3i lo, hi;
  float gap = INFINITY;
  for (int a = 0; a < 3; ++a) {
    const float local = (p[a] - origin_[a]) / cell_size_;
    const int cell = std::clamp(int(std::floor(local)), 0, dims_[a] - 1);
    const int ball_lo = std::clamp(int(std::floor(local - radius / cell_size_)), 0, dims_[a] - 1);
    const int ball_hi = std::clamp(int(std::floor(local + radius / cell_size_)), 0, dims_[a] - 1);
    lo[a] = std::max(ball_lo, cell - 1);
    hi[a] = std::min(ball_hi, cell + 1);
    if (ball_lo < lo[a]) gap = std::min(gap, (local - float(lo[a])) * cell_size_);
    if (ball_hi > hi[a]) gap = std::min(gap, (float(hi[a] + 1) - local) * cell_size_);
  }
  // p's own cell first (when in the block): its triangles are usually the nearest, and a small best
  // distance early lets the box and disc tests skip most of the rest.
  const Eigen::Vector3i own = cell_of(p);
  const bool own_in_block = (own.array() >= lo.array()).all() && (own.array() <= hi.array()).all();
  if (own_in_block) scan_cell(p, cell_index(own.x(), own.y(), own.z()), nearest);
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const size_t c = cell_index(x, y, z);
        if (cell_offsets_[c] == cell_offsets_[c + 1] || (own_in_block && Eigen::Vector3i(x, y, z) == own)) continue;
        // Skip a cell whose box is farther than the best distance so far (and its near ties).
        if (cell_box_distance_sq(p, x, y, z) > nearest.best_sq * kNearTie * kNearTie) continue;
        scan_cell(p, c, nearest);
      }
  r_closest.triangle = nearest.best;
  r_closest.bary = nearest.best_bary;
  const float distance = std::sqrt(nearest.best_sq);
  if (distance * kNearTie > gap) {
    r_distance = std::min(distance, gap);
    return false;
  }
  r_distance = signed_at(p, nearest, r_closest);
  return true;
}

}  // namespace plume::skin
