// Quality on a real groom: hold out 20% and 40% of the guides (farthest-point sampling on the roots
// picks the kept ones), regrow strands at the held-out roots from the kept guides, and compare them
// with the real guides: mean distance (% of the real strand's length, points paired by normalised
// arc length) and % of points inside the body, for each interpolation method.
// Beside them, in the same run:
// - the baseline a few lines write: the k = 4 nearest guide roots, weights 1/d^2, each guide carried
//   into the root's surface frame (the minimal rotation taking its root's normal to the root's) and
//   its points blended by normalised arc length; the default method's error over the baseline's is
//   printed as a ratio (the target is <= 0.8);
// - the "oracle": the best least-squares blend of the same k guides that streamline uses
//   (root-relative, paired by arc length), with weights >= 0 (convex) or any weights summing to 1
//   (affine): the floor a blend of those guides can reach.
// Usage: bench_quality [--detail] [--scale S]                          Sintel (grooms/sintel)
//        bench_quality [--detail] [--scale S] GUIDES MESH.obj [NAME]   another hairstyle: its guides
//                                                (.hair, .ply, .usda or .obj lines) on its mesh
//        bench_quality [--detail] --groom GROOM.yaml     a groom's guides on its mesh, bound with its
//                                                partings and k (e.g. grooms/sintel_parting); the
//                                                baseline does not see the partings
// --detail also prints where the error comes from: each method's mean length error and first-segment
// angle, and streamline's error when grown to the real strands' own lengths (the shape's error).
// --scale S multiplies every coordinate by S first (S = 0.01: a groom modelled in centimetres,
// as if in metres): a method without absolute lengths gives the same errors.
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "groom/guide_curve.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "check/check.h"
#include "interp/interpolate.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"
#include "partings/parting_field.h"

using namespace plume;

namespace {

/// `count` points at uniform normalised arc length along a polyline.
std::vector<Eigen::Vector3f> resample(std::span<const Eigen::Vector3f> points, int count) {
  std::vector<double> arc(points.size(), 0.0);
  for (size_t i = 1; i < points.size(); ++i) arc[i] = arc[i - 1] + (points[i] - points[i - 1]).norm();
  std::vector<Eigen::Vector3f> out(static_cast<size_t>(count));
  size_t seg = 0;
  for (int j = 0; j < count; ++j) {
    const double s = arc.back() * double(j) / double(count - 1);
    while (seg + 2 < points.size() && arc[seg + 1] < s) ++seg;
    const double span = arc[seg + 1] - arc[seg];
    const float t = span > 0.0 ? float(std::clamp((s - arc[seg]) / span, 0.0, 1.0)) : 0.0f;
    out[size_t(j)] = points[seg] + t * (points[seg + 1] - points[seg]);
  }
  return out;
}

double polyline_length(std::span<const Eigen::Vector3f> points) {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

/// Indices of `keep` roots chosen by farthest-point sampling, starting from root 0.
std::vector<size_t> farthest_point_sample(const std::vector<Eigen::Vector3f> &roots, size_t keep) {
  std::vector<float> distance(roots.size(), std::numeric_limits<float>::infinity());
  std::vector<size_t> kept;
  size_t next = 0;
  while (kept.size() < keep) {
    kept.push_back(next);
    for (size_t i = 0; i < roots.size(); ++i) distance[i] = std::min(distance[i], (roots[i] - roots[next]).norm());
    next = size_t(std::max_element(distance.begin(), distance.end()) - distance.begin());
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

/// Mean over strands of the mean distance between paired points, in % of the real strand's length.
double mean_error_percent(const StrandSet &grown, const StrandSet &real, int samples) {
  double sum = 0.0;
  for (size_t s = 0; s < real.strand_count(); ++s) {
    const auto a = resample(grown.points(s), samples), b = resample(real.points(s), samples);
    double d = 0.0;
    for (int j = 0; j < samples; ++j) d += (a[size_t(j)] - b[size_t(j)]).norm();
    sum += 100.0 * d / double(samples) / polyline_length(real.points(s));
  }
  return sum / double(real.strand_count());
}

/// Angle (degrees) between the first segments of two polylines resampled to `samples` points.
double first_angle_degrees(std::span<const Eigen::Vector3f> a_points, std::span<const Eigen::Vector3f> b_points,
                           int samples) {
  const auto a = resample(a_points, samples), b = resample(b_points, samples);
  const Eigen::Vector3f u = (a[1] - a[0]).normalized(), v = (b[1] - b[0]).normalized();
  return std::acos(std::clamp(double(u.dot(v)), -1.0, 1.0)) * 180.0 / 3.14159265358979;
}

/// Where the error of `grown` against `real` comes from, printed on one line: the mean relative
/// length error, the mean first-segment angle and how many strands turn off by more than 45 degrees.
void print_decomposition(const char *held, const char *method, const StrandSet &grown, const StrandSet &real,
                         int samples) {
  double length_error = 0.0, angle = 0.0;
  int off = 0;
  for (size_t s = 0; s < real.strand_count(); ++s) {
    length_error += std::abs(polyline_length(grown.points(s)) / polyline_length(real.points(s)) - 1.0);
    const double a = first_angle_degrees(grown.points(s), real.points(s), samples);
    angle += a;
    off += a > 45.0;
  }
  const double count = double(real.strand_count());
  std::printf("%-9s %-11s length error %.1f%%, first segment off by %.1f deg (%d strands > 45 deg)\n", held, method,
              100.0 * length_error / count, angle / count, off);
}

/// Least-squares weights (summing to 1) of `shapes` for `target`, all paired point by point;
/// returns the mean point distance. Substitutes w_0 = 1 - sum_{i>0} w_i.
double best_affine_blend(const std::vector<std::vector<Eigen::Vector3f>> &shapes,
                         const std::vector<Eigen::Vector3f> &target, Eigen::VectorXd &r_weights) {
  const int n = int(shapes.size()), samples = int(target.size());
  r_weights = Eigen::VectorXd::Zero(n);
  r_weights[0] = 1.0;
  if (n > 1) {
    Eigen::MatrixXd a(3 * samples, n - 1);
    Eigen::VectorXd b(3 * samples);
    for (int j = 0; j < samples; ++j)
      for (int c = 0; c < 3; ++c) {
        b[3 * j + c] = double(target[size_t(j)][c] - shapes[0][size_t(j)][c]);
        for (int i = 1; i < n; ++i)
          a(3 * j + c, i - 1) = double(shapes[size_t(i)][size_t(j)][c] - shapes[0][size_t(j)][c]);
      }
    const Eigen::VectorXd rest = a.colPivHouseholderQr().solve(b);
    r_weights.tail(n - 1) = rest;
    r_weights[0] = 1.0 - rest.sum();
  }
  double d = 0.0;
  for (int j = 0; j < samples; ++j) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) p += r_weights[i] * shapes[size_t(i)][size_t(j)].cast<double>();
    d += (p - target[size_t(j)].cast<double>()).norm();
  }
  return d / double(samples);
}

/// The best blend of a root's bound guides: the guides' shapes are moved to the real strand's root
/// and paired by normalised arc length. `convex`: weights >= 0 (the best of the affine fits over
/// every subset of the guides whose weights are all >= 0; at most 2^k - 1 subsets); otherwise any
/// weights summing to 1 (extrapolation allowed).
double oracle_error_percent(const interp::Binding &binding, const Guides &kept, const StrandSet &real, int samples,
                            bool convex) {
  double sum = 0.0;
  for (size_t s = 0; s < real.strand_count(); ++s) {
    const auto target = resample(real.points(s), samples);
    std::vector<std::vector<Eigen::Vector3f>> shapes;
    for (int slot = 0; slot < binding.k; ++slot) {
      const int32_t g = binding.guide_ids[s * size_t(binding.k) + size_t(slot)];
      if (g < 0) continue;
      auto shape = resample(kept.strands.points(size_t(g)), samples);
      const Eigen::Vector3f offset = target[0] - shape[0];
      for (auto &p : shape) p += offset;
      shapes.push_back(std::move(shape));
    }
    Eigen::VectorXd weights;
    double best = std::numeric_limits<double>::infinity();
    if (!convex) {
      best = best_affine_blend(shapes, target, weights);
    } else {
      for (unsigned subset = 1; subset < (1u << shapes.size()); ++subset) {
        std::vector<std::vector<Eigen::Vector3f>> chosen;
        for (size_t i = 0; i < shapes.size(); ++i)
          if (subset & (1u << i)) chosen.push_back(shapes[i]);
        const double d = best_affine_blend(chosen, target, weights);
        if (weights.minCoeff() >= 0.0) best = std::min(best, d);
      }
    }
    sum += 100.0 * best / polyline_length(real.points(s));
  }
  return sum / double(real.strand_count());
}

/// The baseline: the k = 4 nearest kept guide roots (Euclidean, rest pose), weights 1/d^2 (a guide
/// root at the root takes all the weight), each guide resampled to `points` points by normalised arc
/// length and carried into the root's surface frame by the minimal rotation taking its root's normal
/// to the root's normal, offsets from its root on the skin blended point by point.
StrandSet baseline_strands(const Mesh &mesh, const Guides &kept, const Roots &roots, int points) {
  constexpr int k = 4;
  const size_t guide_count = kept.size();
  std::vector<Eigen::Vector3f> guide_roots(guide_count), guide_normals(guide_count);
  std::vector<std::vector<Eigen::Vector3f>> resampled(guide_count);
  for (size_t g = 0; g < guide_count; ++g) {
    guide_roots[g] = surface_position(mesh, kept.roots[g]);
    guide_normals[g] = surface_normal(mesh, kept.roots[g]);
    resampled[g] = resample(kept.strands.points(g), points);
  }
  StrandSet strands;
  std::vector<Eigen::Vector3f> strand(static_cast<size_t>(points));
  for (size_t r = 0; r < roots.size(); ++r) {
    const Eigen::Vector3f c = surface_position(mesh, roots.points[r]), n = surface_normal(mesh, roots.points[r]);
    std::vector<std::pair<float, size_t>> nearest;
    for (size_t g = 0; g < guide_count; ++g) nearest.emplace_back((guide_roots[g] - c).norm(), g);
    const size_t used = std::min<size_t>(k, guide_count);
    std::partial_sort(nearest.begin(), nearest.begin() + std::ptrdiff_t(used), nearest.end());
    std::vector<float> weights(used);
    float sum = 0.0f;
    for (size_t i = 0; i < used; ++i) {
      weights[i] = nearest[0].first <= 1e-6f * (1.0f + c.norm()) ? (i == 0 ? 1.0f : 0.0f)
                                                                    : 1.0f / (nearest[i].first * nearest[i].first);
      sum += weights[i];
    }
    std::fill(strand.begin(), strand.end(), c);
    for (size_t i = 0; i < used; ++i) {
      const size_t g = nearest[i].second;
      const Eigen::Quaternionf carry = Eigen::Quaternionf::FromTwoVectors(guide_normals[g], n);
      for (int j = 0; j < points; ++j)
        strand[size_t(j)] += (weights[i] / sum) * (carry * (resampled[g][size_t(j)] - guide_roots[g]));
    }
    strands.append(strand, roots.ids[r]);
  }
  return strands;
}

}  // namespace

int main(int argc, char **argv) {
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/";
  float scale = 1.0f;
  bool detail = false;
  if (argc >= 2 && std::string(argv[1]) == "--detail") {
    detail = true;
    --argc;
    ++argv;
  }
  if (argc >= 3 && std::string(argv[1]) == "--scale") {
    scale = std::strtof(argv[2], nullptr);
    argc -= 2;
    argv += 2;
  }
  std::string groom_path;
  if (argc == 3 && std::string(argv[1]) == "--groom" && scale == 1.0f) {
    groom_path = argv[2];
    argc -= 2;
    argv += 2;
  }
  if ((argc != 1 && argc != 3 && argc != 4) || !(scale > 0.0f && scale < 1e6f)) {
    std::fprintf(stderr,
                 "usage: bench_quality [--detail] [--scale S in (0, 1e6)] [GUIDES MESH.obj [NAME]]\n"
                 "       bench_quality [--detail] --groom GROOM.yaml\n");
    return 2;
  }
  GroomDesc groom;
  if (!groom_path.empty()) {
    try {
      groom = io::read_groom_file(groom_path);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "bench_quality: %s\n", e.what());
      return 2;
    }
  }
  const std::string guides_path =
      !groom_path.empty() ? groom.guides_path : argc >= 3 ? argv[1] : folder + "sintel_guides.hair";
  const std::string mesh_path = !groom_path.empty() ? groom.emitter_path : argc >= 3 ? argv[2] : folder + "sintel.obj";
  std::string name = !groom_path.empty() ? groom.name + " (with its partings)"
                     : argc == 4           ? argv[3]
                     : argc >= 3           ? guides_path
                                           : "Sintel";
  if (scale != 1.0f) {
    char factor[32];
    std::snprintf(factor, sizeof factor, " (coordinates x %g)", double(scale));
    name += factor;
  }
  Mesh mesh;
  Guides all;
  try {
    mesh = io::read_obj_mesh(mesh_path);
    StrandSet guide_strands = io::read_strands(guides_path);
    if (scale != 1.0f) {
      for (Eigen::Vector3f &p : mesh.positions) p *= scale;
      mesh.compute_normals();
      for (Eigen::Vector3f &p : guide_strands.positions) p *= scale;
    }
    all = bind_guides(MeshQuery(mesh), guide_strands, guides_path);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench_quality: %s\n", e.what());
    return 2;
  }
  if (all.size() < 10) {
    std::fprintf(stderr, "bench_quality: %s: %zu guides, at least 10 needed to hold some out\n", guides_path.c_str(),
                 all.size());
    return 2;
  }
  const MeshQuery query(mesh);
  const int points = 32;
  std::vector<Eigen::Vector3f> root_positions;
  for (size_t g = 0; g < all.size(); ++g) root_positions.push_back(all.strands.points(g)[0]);

  std::printf("%s hold-out quality: %zu guides, %zu-triangle mesh, %d cores, %d threads\n", name.c_str(), all.size(),
              mesh.triangle_count(), omp_get_num_procs(), omp_get_max_threads());
  std::printf("%-9s %-11s %6s %7s %12s %10s %10s\n", "held out", "method", "kept", "regrown", "error %len",
              "inside %", "bind+grow");

  for (const double held_out : {0.2, 0.4}) {
    const size_t keep = size_t(std::lround(double(all.size()) * (1.0 - held_out)));
    const std::vector<size_t> kept_ids = farthest_point_sample(root_positions, keep);
    std::vector<bool> is_kept(all.size(), false);
    for (size_t g : kept_ids) is_kept[g] = true;
    Guides kept;
    Roots roots;
    StrandSet real;
    for (size_t g = 0; g < all.size(); ++g) {
      if (is_kept[g]) {
        kept.strands.append(all.strands.points(g), g);
        kept.roots.push_back(all.roots[g]);
      } else {
        roots.points.push_back(all.roots[g]);
        roots.ids.push_back(g);
        real.append(all.strands.points(g), g);
      }
    }

    using Method = InterpolationSettings::Method;
    const std::pair<Method, const char *> methods[] = {
        {Method::streamline, "streamline"}, {Method::fur, "fur"}, {Method::linear, "linear"}};
    interp::Binding streamline_binding;
    double streamline_error = 0.0;
    for (const auto &[method, method_name] : methods) {
      InterpolationSettings settings;
      settings.method = method;
      interp::GrowOptions options;
      options.points_per_strand = points;
      StrandSet grown;
      const auto start = std::chrono::steady_clock::now();
      // With --groom, the groom's partings (made on the kept guides) and its k.
      std::unique_ptr<partings::PartingField> parting_field;
      if (!groom_path.empty()) {
        settings.k = groom.interpolation.k;
        parting_field = std::make_unique<partings::PartingField>(mesh, kept, groom.partings);
      }
      interp::Binding binding = interp::bind(mesh, kept, roots, settings,
                                             parting_field && !parting_field->empty() ? parting_field.get() : nullptr);
      interp::grow(binding, mesh, query, roots, kept.strands, options, grown);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::vector<uint64_t> examples;
      const size_t inside = check::count_points_inside(grown, query, 0.0f, 1, examples);
      const double error = mean_error_percent(grown, real, points);
      std::printf("%-9s %-11s %6zu %7zu %12.2f %10.2f %8.1fms\n", held_out == 0.2 ? "20%" : "40%", method_name, keep,
                  roots.size(), error, 100.0 * double(inside) / double(grown.point_count()), seconds * 1e3);
      if (detail) print_decomposition(held_out == 0.2 ? "20%" : "40%", method_name, grown, real, points);
      if (detail && method == Method::streamline) {
        // The same strands grown to the real strands' own lengths: what is left is the shape's error.
        interp::Binding true_length = binding;
        std::vector<CurvePiece> curve;
        for (size_t s = 0; s < real.strand_count(); ++s) {
          guide_curve(real.points(s), 1e-6f * interp::field_cell_fraction * binding.length_unit, curve);
          true_length.lengths[s] = float(curve_length(curve));
        }
        StrandSet regrown;
        interp::grow(true_length, mesh, query, roots, kept.strands, options, regrown);
        std::printf("%-9s %-11s %6zu %7zu %12.2f   (grown to the real strands' lengths)\n",
                    held_out == 0.2 ? "20%" : "40%", method_name, keep, roots.size(),
                    mean_error_percent(regrown, real, points));
      }
      if (method == Method::streamline) {
        streamline_binding = std::move(binding);
        streamline_binding.partings = nullptr;  // the parting field is this iteration's
        streamline_error = error;
      }
    }
    {
      const auto start = std::chrono::steady_clock::now();
      const StrandSet grown = baseline_strands(mesh, kept, roots, points);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::vector<uint64_t> examples;
      const size_t inside = check::count_points_inside(grown, query, 0.0f, 1, examples);
      const double error = mean_error_percent(grown, real, points);
      std::printf("%-9s %-11s %6zu %7zu %12.2f %10.2f %8.1fms\n", held_out == 0.2 ? "20%" : "40%", "baseline", keep,
                  roots.size(), error, 100.0 * double(inside) / double(grown.point_count()), seconds * 1e3);
      if (detail) print_decomposition(held_out == 0.2 ? "20%" : "40%", "baseline", grown, real, points);
      std::printf("%-9s streamline / baseline error: %.3f (target <= 0.8)\n", held_out == 0.2 ? "20%" : "40%",
                  streamline_error / error);
    }
    for (const bool convex : {true, false})
      std::printf("%-9s %-11s %6zu %7zu %12.2f %10s\n", held_out == 0.2 ? "20%" : "40%",
                  convex ? "best convex" : "best affine", keep, roots.size(),
                  oracle_error_percent(streamline_binding, kept, real, points, convex), "-");
  }
  return 0;
}
