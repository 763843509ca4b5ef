#include "dynamics/guide_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "dynamics/rigid_motion.h"
#include "dynamics/skin_shapes.h"
#include "dynamics/tridiagonal.h"
#include "dynamics/wind.h"
#include "groom/error.h"
#include "groom/mesh_query.h"

// The model and the equations solved here are derived in docs/dynamics.md. Notation: joints
// x_0 .. x_{n-1} of one guide; segment i joins x_{i-1} and x_i (i >= 1), rest length l_i, unit
// direction e_i; joints 0 and 1 are kinematic (root and first segment clamped to the skin frame),
// joints 2 .. n-1 are free, with mass m_j and inverse mass w_j = 1 / m_j (w = 0 when kinematic).

namespace plume::dynamics {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Relative tolerance on segment lengths at the end of a substep.
constexpr double kLengthTolerance = 1e-8;
// Share of the centripetal term h |dv_perp|^2 / l asked of the first velocity projection (see
// project_velocities): 1/3 puts a segment turning by theta at angle theta + O(theta^5) after the
// length projection.
constexpr double kCentripetal = 1.0 / 3.0;
// Newton iterations of the post-stabilisation before the exact root-to-tip fallback.
constexpr int kMaxProjectionIterations = 8;
// Rounds of (push out of shapes, restore lengths) per substep.
constexpr int kCollisionRounds = 2;
// A joint in contact keeps this fraction of its mobility along the contact normal during the
// length projection, so that the system stays non-singular when a segment points into a shape.
constexpr double kContactNormalMobility = 0.01;
// Fewer guides than this are stepped on one thread: a parallel region costs more than they do.
constexpr int64_t kParallelGuides = 128;

Vector3d unit_or(const Vector3d &d, const Vector3d &fallback) {
  const double len = d.norm();
  return len > 1e-300 ? Vector3d(d * (1.0 / len)) : fallback;
}

// The minimal rotation taking unit vector a to unit vector b (parallel transport along the
// strand):  R = I + [w]x + [w]x^2 / (1 + c),  w = a x b, c = a . b.
Matrix3d transport(const Vector3d &a, const Vector3d &b) {
  const Vector3d w = a.cross(b);
  const double c = a.dot(b);
  if (c < -1.0 + 1e-12) {
    // Opposite directions: a half turn about any axis perpendicular to a.
    const Vector3d axis = a.unitOrthogonal();
    return 2.0 * axis * axis.transpose() - Matrix3d::Identity();
  }
  Matrix3d wx;
  wx << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return Matrix3d::Identity() + wx + wx * wx / (1.0 + c);
}

// rotation <- T(a -> b) rotation without forming T: on each column v,
//   T v = c v + w x v + w (w . v) / (1 + c)   ([w]x^2 v = w (w . v) - |w|^2 v, |w|^2 = 1 - c^2).
void transport_frame(const Vector3d &a, const Vector3d &b, Matrix3d &rotation) {
  const double c = a.dot(b);
  if (c < -1.0 + 1e-12) {
    rotation = transport(a, b) * rotation;
    return;
  }
  const Vector3d w = a.cross(b);
  const Vector3d w_scaled = w / (1.0 + c);
  for (int k = 0; k < 3; ++k) {
    const Vector3d column = rotation.col(k);
    rotation.col(k) = c * column + w.cross(column) + w.dot(column) * w_scaled;
  }
}

void check_settings(const DynamicsSettings &s) {
  auto fail = [&](const std::string &what) { throw InputError(s.loc, "dynamics." + what); };
  if (s.substeps < 1) fail("substeps: expected an integer >= 1, got " + std::to_string(s.substeps));
  if (!(s.fps > 0.0f) || !std::isfinite(s.fps)) fail("fps: expected a positive number, got " + std::to_string(s.fps));
  if (!(s.mass_per_unit > 0.0f)) fail("mass_per_unit: expected a positive number, got " + std::to_string(s.mass_per_unit));
  if (!(s.damping >= 0.0f)) fail("damping: expected >= 0, got " + std::to_string(s.damping));
  if (!(s.drag >= 0.0f)) fail("drag: expected >= 0, got " + std::to_string(s.drag));
  if (!(s.stiffness_scale >= 0.0f)) fail("stiffness_scale: expected >= 0, got " + std::to_string(s.stiffness_scale));
  if (!(s.collision_margin >= 0.0f)) fail("collision_margin: expected >= 0, got " + std::to_string(s.collision_margin));
  if (!(s.emitter_friction >= 0.0f)) fail("emitter_friction: expected >= 0, got " + std::to_string(s.emitter_friction));
  if (!s.gravity.allFinite() || !s.wind.allFinite()) fail("gravity/wind: expected finite vectors");
  for (float k : s.stiffness.value)
    if (!(k >= 0.0f)) fail("stiffness: expected values >= 0, got " + std::to_string(k));
}

}  // namespace

struct GuideSimulator::State {
  DynamicsSettings settings;
  std::vector<int64_t> offsets;
  std::vector<SurfacePoint> roots;

  // Per guide: root frames at rest, at the previous and the current pose; work of the last
  // substep.
  std::vector<FramePose> root_rest, root_from, root_to;
  std::vector<int64_t> guide_solves, guide_rows, guide_queries;

  // Per joint, fixed after construction.
  std::vector<Vector3d> rest_local;   // rest point in its root's rest surface frame
  std::vector<double> rest_length;    // l_i of the segment ending at this joint (0 for joint 0)
  std::vector<double> inv_rest_length;  // 1 / l_i (0 for joint 0)
  std::vector<double> mass, inv_mass;  // m_j, w_j (w = 0 for the kinematic joints 0 and 1)
  std::vector<double> stiffness;      // k_i of the segment ending at this joint
  std::vector<double> emitter_margin;  // clearance kept from the emitter; < 0: not tested
  std::vector<double> rest_clearance;  // signed distance to the rest emitter at rest (if tested)
  std::vector<SurfacePoint> rest_closest;  // closest rest emitter point at rest (first search hint)

  // Per joint, the state.
  std::vector<Vector3d> x, v;
  std::vector<Vector3d> gold;    // gold offset of segment i in the frame of segment i-1
  std::vector<double> tension;   // constraint force of segment i from the last substep
  std::vector<Vector3d> query_point;  // position at the last emitter query
  std::vector<double> query_clearance;  // |distance| to the emitter at that query (-inf: none yet)
  std::vector<double> skin_travel;      // how far the skin has moved since that query (bound)
  std::vector<SurfacePoint> query_closest;  // closest emitter point at that query (search hint)

  // Per joint scratch, overwritten every substep (no allocation while stepping).
  std::vector<Vector3d> dir, target, velocity_rhs, correction, contact_normal, contact_velocity;
  std::vector<double> lower, diag, upper, scalar_rhs, contact_friction;

  // Colliders.
  SkinShapes shapes;
  std::vector<FramePose> shape_frames_from, shape_frames_to;
  std::vector<PosedShape> shapes_start, shapes_end;
  std::vector<Eigen::Vector3f> rest_positions;  // emitter vertices at rest
  Mesh mesh_from, mesh_to, mesh_sub;  // emitter at the previous pose, current pose, substep end
  std::vector<Eigen::Vector3f> sub_start_positions;
  // The emitter's search tree on mesh_sub (no kd-tree start: every query has a hint), built by
  // the first joint of a substep that needs an exact query: once the guides stand clear of the
  // skin, most substeps need none. query_once is renewed when mesh_sub moves.
  std::unique_ptr<MeshQuery> query;
  std::unique_ptr<std::once_flag> query_once;
  std::exception_ptr query_error;  // a failed build, rethrown after the substep
  // The emitter's motion over the current substep as a best-fit rigid motion plus the largest
  // vertex departure from it (the non-rigid residual), for the query-skipping bound.
  RigidMotion skin_motion;

  bool posed = false;

  size_t guide_count() const { return roots.size(); }

  void reset_guide(size_t g, const RigidMotion &from_rest);
  void pose_roots(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns);
  const MeshQuery *emitter_query();
  void copy_positions(std::vector<Eigen::Vector3f> &r_positions) const;
  void substep_guide(size_t g, double s0, double s1, double h, double time_end);
  bool collide(int64_t begin, int64_t n, double h, int64_t &r_queries);
  int project_lengths(int64_t begin, int64_t n);
  void project_velocities(int64_t begin, int64_t n, const Eigen::Vector3d &first_velocity, const Eigen::Vector3d *v_in,
                          Eigen::Vector3d *v_out, double *r_lambda, double turn_h = 0.0);
};

// The emitter's tree for the current substep, built on first use (thread-safe); null if the
// build failed (query_error holds why).
const MeshQuery *GuideSimulator::State::emitter_query() {
  std::call_once(*query_once, [this] {
    try {
      mesh_sub.compute_normals();
      query = std::make_unique<MeshQuery>(mesh_sub, MeshQuery::Start::hint_only);
    } catch (...) {
      query_error = std::current_exception();
    }
  });
  return query.get();
}

namespace {

// The root frame of guide g on `posed_mesh`, turned by its entry of `root_turns` (if any) about
// the guide's first point `first_local` (in the frame): with R' = R q and o' = o + R (c - q c), the
// first point o' + R' c = o + R c stays where the skin carries it.
FramePose root_frame(const Mesh &posed_mesh, const SurfacePoint &root, std::span<const Eigen::Quaternionf> root_turns,
                     size_t g, const Vector3d &first_local) {
  FramePose pose = FramePose::from(surface_frame(posed_mesh, root));
  if (root_turns.empty()) return pose;
  const Eigen::Quaternionf &turn = root_turns[g];
  if (turn.w() == 1.0f && turn.vec() == Eigen::Vector3f::Zero()) return pose;
  const Eigen::Quaterniond q = turn.cast<double>();
  pose.origin += pose.rotation * (first_local - q * first_local);
  pose.rotation = (pose.rotation * q).normalized();
  return pose;
}

}  // namespace

// root_to <- the root frames on `posed_mesh` (a per-guide loop: parallel like the substeps).
void GuideSimulator::State::pose_roots(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns) {
#pragma omp parallel for schedule(static) if (guide_count() >= kParallelGuides)
  for (int64_t g = 0; g < int64_t(guide_count()); ++g)
    root_to[size_t(g)] = root_frame(posed_mesh, roots[size_t(g)], root_turns, size_t(g), rest_local[size_t(offsets[size_t(g)])]);
}

// The float view of the joint positions.
void GuideSimulator::State::copy_positions(std::vector<Eigen::Vector3f> &r_positions) const {
  const int64_t count = int64_t(r_positions.size());
#pragma omp parallel for schedule(static) if (guide_count() >= kParallelGuides)
  for (int64_t p = 0; p < count; ++p) r_positions[size_t(p)] = x[size_t(p)].cast<float>();
}

// Sets guide g at rest on the current pose (root_to), and solves compensated gravity.
// `from_rest`: the emitter's best rigid motion from rest to the current pose.
void GuideSimulator::State::reset_guide(size_t g, const RigidMotion &from_rest) {
  const int64_t begin = offsets[g], n = offsets[g + 1] - begin;
  const FramePose &frame = root_to[g];
  for (int64_t j = 0; j < n; ++j) {
    x[begin + j] = frame.to_world(rest_local[begin + j]);
    v[begin + j] = Vector3d::Zero();
    tension[begin + j] = 0.0;
    skin_travel[begin + j] = 0.0;
    query_point[begin + j] = x[begin + j];
    query_closest[begin + j] = rest_closest[begin + j];
    // The first emitter clearance without a query. The joint stood rest_clearance outside the
    // rest emitter; its root frame carried it to x, which the emitter's rigid motion maps back
    // to a point `shift` away from its rest place, so (distance being 1-Lipschitz, and the skin
    // within `residual` of the rigidly carried rest skin) it is at least
    // rest_clearance - shift - residual outside. When that is not above the margin, the first
    // step queries (the hint, its closest point at rest, is then near the answer).
    double clearance = -std::numeric_limits<double>::infinity();
    if (emitter_margin[begin + j] >= 0.0) {
      const double shift = (x[begin + j] - from_rest.apply(root_rest[g].to_world(rest_local[begin + j]))).norm();
      const double bound = rest_clearance[begin + j] - shift - from_rest.residual;
      if (bound > emitter_margin[begin + j]) clearance = bound;
    }
    query_clearance[begin + j] = clearance;
  }
  if (n < 3) return;
  const Vector3d gravity = settings.gravity.cast<double>();
  // Outboard load L_i = sum_{j >= i} m_j g, and the rest equilibrium of the part of the guide
  // beyond joint i-1: L_i + S_i + tau_i e_i = 0, where S_i is the spring force of segment i and
  // tau_i its tension. The axial part of L_i is carried by the tension (tau_i = -L_i . e_i);
  // with compensation the spring carries the rest: S_i = -(L_i - (L_i . e_i) e_i), so the gold
  // offset becomes l_i e_i + S_i / k_i. See docs/dynamics.md, "Compensated gravity".
  Vector3d load = Vector3d::Zero();
  for (int64_t i = n - 1; i >= 2; --i) {
    load += mass[begin + i] * gravity;
    const Vector3d e = unit_or(x[begin + i] - x[begin + i - 1], Vector3d::UnitZ());
    tension[begin + i] = -load.dot(e);
    Vector3d offset = rest_length[begin + i] * e;
    const double k = stiffness[begin + i];
    if (settings.compensate_gravity && k > 0.0) offset -= (load - load.dot(e) * e) / k;
    target[begin + i] = offset;
  }
  // Express each offset in the frame of the previous segment (gold positions): the frame of
  // segment 1 is the skin frame, each next one is parallel-transported along the strand.
  Matrix3d rotation = frame.rotation.toRotationMatrix();
  Vector3d d_prev = unit_or(x[begin + 1] - x[begin], frame.rotation * Vector3d::UnitZ());
  for (int64_t i = 2; i < n; ++i) {
    gold[begin + i] = rotation.transpose() * target[begin + i];
    const Vector3d d = unit_or(x[begin + i] - x[begin + i - 1], d_prev);
    rotation = transport(d_prev, d) * rotation;
    d_prev = d;
  }
}

// Pushes the free joints of one guide out of every shape and the emitter, recording for each
// joint in contact the outward normal, the surface velocity and the friction coefficient.
// Returns whether any joint was pushed; counts the exact emitter queries in r_queries.
bool GuideSimulator::State::collide(int64_t begin, int64_t n, double h, int64_t &r_queries) {
  const double margin = settings.collision_margin;
  bool pushed = false;
  for (int64_t j = begin + 2; j < begin + n; ++j) {
    for (size_t s = 0; s < shapes_end.size(); ++s) {
      Vector3d normal;
      double axis_param;
      const double d = shape_distance(shapes_end[s], x[j], normal, axis_param);
      if (d >= margin) continue;
      x[j] += (margin - d) * normal;
      pushed = true;
      contact_normal[j] = normal;
      contact_friction[j] = shapes_end[s].friction;
      const Vector3d velocity_a = (shapes_end[s].a - shapes_start[s].a) / h;
      const Vector3d velocity_b = (shapes_end[s].b - shapes_start[s].b) / h;
      contact_velocity[j] = velocity_a + axis_param * (velocity_b - velocity_a);
    }
    const double joint_margin = emitter_margin[j];
    if (!settings.collide_with_emitter || joint_margin < 0.0) continue;
    // Query skipping. The distance to the surface is 1-Lipschitz in the point, does not change
    // when point and surface move rigidly together, and changes by at most the residual when the
    // surface deforms. query_point is the last queried point carried by the skin's rigid motion
    // and skin_travel the summed residuals since, so this is a lower bound of the distance: while
    // it stays above the margin the query can be skipped.
    const double bound = query_clearance[j] - (x[j] - query_point[j]).norm() - skin_travel[j];
    if (bound > joint_margin) continue;
    const MeshQuery *tree = emitter_query();
    if (!tree) return pushed;
    SurfacePoint closest;
    const double d = tree->signed_distance(x[j], query_closest[j], closest);
    ++r_queries;
    query_closest[j] = closest;
    if (d < joint_margin) {
      const Vector3d normal = surface_normal(mesh_sub, closest).cast<double>();
      x[j] = surface_position(mesh_sub, closest).cast<double>() + joint_margin * normal;
      pushed = true;
      contact_normal[j] = normal;
      contact_friction[j] = settings.emitter_friction;
      const Eigen::Vector3i &t = mesh_sub.triangles[closest.triangle];
      Vector3d travel = Vector3d::Zero();
      for (int k = 0; k < 3; ++k)
        travel += double(closest.bary[k]) * (mesh_sub.positions[t[k]] - sub_start_positions[t[k]]).cast<double>();
      contact_velocity[j] = travel / h;
    }
    query_point[j] = x[j];
    query_clearance[j] = std::max(d, joint_margin);  // after a push-out the joint sits at the margin
    skin_travel[j] = 0.0;
  }
  return pushed;
}

// Post-stabilisation: Newton iterations on C_i(x) = |x_i - x_{i-1}| - l_i = 0 with the mass-
// weighted step dx = W J^T delta, (J W J^T) delta = -C, a tridiagonal system. A joint in contact
// moves (almost) only in its tangent plane: W_j = w_j (I - (1 - eps) n n^T). The displacements
// are added to `correction` (they become velocity, see substep_guide). Returns the number of
// tridiagonal solves.
int GuideSimulator::State::project_lengths(int64_t begin, int64_t n) {
  const int64_t rows = n - 2;
  double *lo = lower.data() + begin, *di = diag.data() + begin, *up = upper.data() + begin;
  double *rhs = scalar_rhs.data() + begin;
  Vector3d *e = dir.data() + begin;
  auto apply_w = [&](int64_t j, const Vector3d &u) -> Vector3d {
    const Vector3d &normal = contact_normal[begin + j];
    return inv_mass[begin + j] * (u - (1.0 - kContactNormalMobility) * normal.dot(u) * normal);
  };
  bool contacts = false;
  for (int64_t j = 2; j < n; ++j) contacts = contacts || contact_normal[begin + j].squaredNorm() > 0.0;
  int solves = 0;
  for (int iteration = 0;; ++iteration) {
    bool converged = true;
    for (int64_t i = 2; i < n; ++i) {
      const Vector3d d = x[begin + i] - x[begin + i - 1];
      const double len = d.norm();
      if (len > 1e-300) e[i] = d * (1.0 / len);
      rhs[i - 2] = rest_length[begin + i] - len;
      converged = converged && std::abs(rhs[i - 2]) <= kLengthTolerance * rest_length[begin + i];
    }
    if (converged) return solves;
    if (iteration == kMaxProjectionIterations) break;
    for (int64_t i = 2; i < n; ++i) {
      const int64_t r = i - 2;
      if (contacts) {
        di[r] = e[i].dot(apply_w(i, e[i])) + (i > 2 ? e[i].dot(apply_w(i - 1, e[i])) : 0.0);
        up[r] = i + 1 < n ? -e[i].dot(apply_w(i, e[i + 1])) : 0.0;
      } else {  // W_j = w_j I: the plain matrix of project_velocities
        di[r] = inv_mass[begin + i] + (i > 2 ? inv_mass[begin + i - 1] : 0.0);
        up[r] = i + 1 < n ? -inv_mass[begin + i] * e[i].dot(e[i + 1]) : 0.0;
      }
      lo[r] = i > 2 ? up[r - 1] : 0.0;
    }
    solve_tridiagonal({lo, size_t(rows)}, {di, size_t(rows)}, {up, size_t(rows)}, {rhs, size_t(rows)});
    ++solves;
    for (int64_t j = 2; j < n; ++j) {
      Vector3d impulse = rhs[j - 2] * e[j];
      if (j + 1 < n) impulse -= rhs[j - 1] * e[j + 1];
      const Vector3d step = contacts ? apply_w(j, impulse) : Vector3d(inv_mass[begin + j] * impulse);
      x[begin + j] += step;
      correction[begin + j] += step;
    }
  }
  // Not converged (a violent step): restore the lengths exactly from root to tip.
  for (int64_t i = 2; i < n; ++i) {
    const Vector3d exact = x[begin + i - 1] + rest_length[begin + i] * unit_or(x[begin + i] - x[begin + i - 1], e[i]);
    correction[begin + i] += exact - x[begin + i];
    x[begin + i] = exact;
  }
  return solves;
}

// Velocity-level inextensibility: v = v' + W J^T lambda with J v = b, J_i v = e_i . (v_i - v_{i-1}):
//   (w_i + w_{i-1}) lambda_i - w_{i-1} (e_{i-1} . e_i) lambda_{i-1} - w_i (e_i . e_{i+1}) lambda_{i+1}
//     = b_i - e_i . (v'_i - v'_{i-1}),
// a symmetric positive definite tridiagonal system (w_1 = 0: joint 1 moves with the skin at
// `first_velocity`). b = 0 makes the velocities tangent to the constraints. With turn_h = h > 0,
// b_i = -kCentripetal h |dv'_perp,i|^2 / l_i: a segment whose relative velocity dv has the part
// dv_perp across it turns, and the step x += h v leaves it longer by about h^2 |dv_perp|^2 / (2 l);
// asking for that inward velocity up front starts the length projection much closer to the
// constraints (fewer Newton solves), and the multipliers then include the centripetal tension.
// Uses the directions in `dir`; v_in and v_out are joint-indexed from the guide's first joint and
// may alias; r_lambda gets the n - 2 multipliers.
void GuideSimulator::State::project_velocities(int64_t begin, int64_t n, const Vector3d &first_velocity,
                                               const Vector3d *v_in, Vector3d *v_out, double *r_lambda,
                                               double turn_h) {
  const int64_t rows = n - 2;
  const Vector3d *e = dir.data() + begin;
  const double *w = inv_mass.data() + begin, *inv_l = inv_rest_length.data() + begin;
  const double centripetal = kCentripetal * turn_h;
  double *lo = lower.data() + begin, *di = diag.data() + begin, *up = upper.data() + begin;
  for (int64_t i = 2; i < n; ++i) {
    const int64_t r = i - 2;
    const Vector3d &v_prev = i > 2 ? v_in[i - 1] : first_velocity;
    const double w_prev = i > 2 ? w[i - 1] : 0.0;
    di[r] = w[i] + w_prev;
    lo[r] = i > 2 ? -w_prev * e[i - 1].dot(e[i]) : 0.0;
    up[r] = i + 1 < n ? -w[i] * e[i].dot(e[i + 1]) : 0.0;
    const Vector3d dv = v_in[i] - v_prev;
    const double axial = e[i].dot(dv);
    r_lambda[r] = -axial - centripetal * (dv.squaredNorm() - axial * axial) * inv_l[i];
  }
  solve_tridiagonal({lo, size_t(rows)}, {di, size_t(rows)}, {up, size_t(rows)}, {r_lambda, size_t(rows)});
  for (int64_t j = 2; j < n; ++j) {
    Vector3d impulse = r_lambda[j - 2] * e[j];
    if (j + 1 < n) impulse -= r_lambda[j - 1] * e[j + 1];
    v_out[j] = v_in[j] + w[j] * impulse;
  }
}

void GuideSimulator::State::substep_guide(size_t g, double s0, double s1, double h, double time_end) {
  const int64_t begin = offsets[g], n = offsets[g + 1] - begin;
  const FramePose f0 = FramePose::interpolate(root_from[g], root_to[g], s0);
  const FramePose f1 = FramePose::interpolate(root_from[g], root_to[g], s1);
  // Kinematic joints: root and the end of the first segment, carried by the skin frame.
  const Vector3d root_end = f1.to_world(rest_local[begin]);
  const Vector3d first_end = f1.to_world(rest_local[begin + 1]);
  const Vector3d first_velocity = (first_end - x[begin + 1]) / h;
  v[begin] = (root_end - x[begin]) / h;
  guide_solves[g] = 0;
  guide_rows[g] = 0;
  guide_queries[g] = 0;
  if (n < 3) {
    v[begin + 1] = first_velocity;
    x[begin] = root_end;
    x[begin + 1] = first_end;
    return;
  }
  const int64_t rows = n - 2;
  Vector3d *xs = x.data() + begin, *vs = v.data() + begin, *e = dir.data() + begin, *goal = target.data() + begin;
  Vector3d *vel = velocity_rhs.data() + begin;
  const double *m = mass.data() + begin, *k = stiffness.data() + begin;
  double *tau = tension.data() + begin;
  double *lo = lower.data() + begin, *di = diag.data() + begin, *up = upper.data() + begin;
  double *lambda = scalar_rhs.data() + begin;

  // 1. Segment directions and gold targets: G_i = R_{i-1} gold_i, with R_1 the skin frame and
  //    R_i = T(e_{i-1} -> e_i) R_{i-1} (frames held fixed over the substep).
  Matrix3d rotation = f1.rotation.toRotationMatrix();
  Vector3d d_prev = unit_or(first_end - root_end, f1.rotation * Vector3d::UnitZ());
  for (int64_t i = 2; i < n; ++i) {
    e[i] = unit_or(xs[i] - xs[i - 1], d_prev);
    goal[i] = rotation * gold[begin + i];
    transport_frame(d_prev, e[i], rotation);
    d_prev = e[i];
  }

  // 2. Implicit predictor (backward Euler on the linear forces), one row per free joint j:
  //    (m_j + h a_j + h gamma_j + h^2 (c_j + c_{j+1})) v'_j - h^2 c_j v'_{j-1} - h^2 c_{j+1} v'_{j+1}
  //      = m_j v_j + h f_j,
  //    f_j = m_j g + a_j wind_j + gamma_j vskin_j + k_j (x_{j-1} + G_j - x_j) - k_{j+1} (x_j + G_{j+1} - x_{j+1})
  //          + tau_j e_j - tau_{j+1} e_{j+1}
  //    a_j = drag m_j |v_j - wind_j| (quadratic air drag, linearised), gamma_j = damping m_j
  //    toward the velocity vskin_j the joint would have if carried rigidly by the root frame.
  //    c_i = k_i + max(0, -tau_i) / l_i: the bending spring plus the geometric stiffness of the
  //    segment's tension (d(tau e)/dx = tau / l (I - e e^T), taken isotropic: its axial part is
  //    overridden by the constraints). Without it a heavily loaded chain (the top of a long
  //    hanging guide) sees its tension explicitly and zigzags at large steps.
  const Vector3d gravity = settings.gravity.cast<double>();
  const Matrix3d skin_turn = f1.rotation.toRotationMatrix() * f0.rotation.toRotationMatrix().transpose();
  const double h2 = h * h, inv_h = 1.0 / h;
  const double *inv_l = inv_rest_length.data() + begin;
  WindField air(settings, time_end);
  auto coupling = [&](int64_t i) { return i < n ? k[i] + std::max(0.0, -tau[i]) * inv_l[i] : 0.0; };
  const double c_first = coupling(2);
  double c = c_first;  // coupling of segment j, carried from the previous row
  for (int64_t j = 2; j < n; ++j) {
    const int64_t r = j - 2;
    const double k_next = j + 1 < n ? k[j + 1] : 0.0;
    const double c_next = coupling(j + 1);
    const Vector3d wind = air.at(xs[j]);
    const double a = settings.drag * m[j] * (vs[j] - wind).norm();
    const double gamma = settings.damping * m[j];
    const Vector3d skin_velocity = (skin_turn * (xs[j] - f0.origin) + f1.origin - xs[j]) * inv_h;
    Vector3d force = m[j] * gravity + a * wind + gamma * skin_velocity + k[j] * (xs[j - 1] + goal[j] - xs[j]) +
                     tau[j] * e[j];
    if (j + 1 < n) force -= k_next * (xs[j] + goal[j + 1] - xs[j + 1]) + tau[j + 1] * e[j + 1];
    di[r] = m[j] + h * (a + gamma) + h2 * (c + c_next);
    lo[r] = -h2 * c;
    up[r] = -h2 * c_next;
    vel[j] = m[j] * vs[j] + h * force;
    c = c_next;
  }
  vel[2] += h2 * c_first * first_velocity;  // the kinematic neighbour's term moves to the right side
  solve_tridiagonal({lo, size_t(rows)}, {di, size_t(rows)}, {up, size_t(rows)}, {vel + 2, size_t(rows)});

  // 3. Velocity-level inextensibility at the start directions (see project_velocities), with
  //    the centripetal inward velocity of turning segments; the multipliers are impulses,
  //    lambda / h the tension force carried to the next predictor, so a guide at rest stays at
  //    rest.
  project_velocities(begin, n, first_velocity, vel, vs, lambda, h);
  for (int64_t j = 2; j < n; ++j) tau[j] += lambda[j - 2] * inv_h;

  // 4. Positions; kinematic joints placed on the skin.
  xs[0] = root_end;
  xs[1] = first_end;
  vs[1] = first_velocity;
  for (int64_t j = 2; j < n; ++j) {
    xs[j] += h * vs[j];
    contact_normal[begin + j] = Vector3d::Zero();
    correction[begin + j] = Vector3d::Zero();
  }
  if (settings.collide_with_emitter) {
    for (int64_t j = begin + 2; j < begin + n; ++j) {
      skin_travel[j] += skin_motion.residual;
      query_point[j] = skin_motion.apply(query_point[j]);
    }
  }

  // 5. Collisions and exact lengths: push out, then restore lengths moving contacts tangentially.
  int solves = 2;
  bool pushed = true;
  for (int round = 0; round < kCollisionRounds && pushed; ++round) {
    pushed = collide(begin, n, h, guide_queries[g]);
    solves += project_lengths(begin, n);
  }

  // 6. The length corrections become velocity (v += dx / h): otherwise a swinging chain, whose
  //    linearised step drifts outward and is pulled back, would gain potential energy at large
  //    steps. Push-outs do not: contact velocities are corrected below instead.
  //    Then the velocities are made tangent to the constraints at the final directions (left in
  //    `dir` by project_lengths), which removes the stretching part of that correction.
  for (int64_t j = 2; j < n; ++j) vs[j] += correction[begin + j] * inv_h;
  project_velocities(begin, n, first_velocity, vs, vs, lambda);
  ++solves;

  // 7. Contact velocities, relative to the moving surface: no inward normal part, Coulomb
  //    friction on the tangential part (|dv_t| <= mu |v_n|).
  for (int64_t j = 2; j < n; ++j) {
    const Vector3d &normal = contact_normal[begin + j];
    if (normal.squaredNorm() == 0.0) continue;
    const Vector3d &surface = contact_velocity[begin + j];
    Vector3d relative = vs[j] - surface;
    const double vn = relative.dot(normal);
    if (vn >= 0.0) continue;
    Vector3d tangential = relative - vn * normal;
    const double vt = tangential.norm();
    const double keep = vt > 0.0 ? std::max(0.0, 1.0 - contact_friction[begin + j] * (-vn) / vt) : 0.0;
    vs[j] = surface + keep * tangential;
  }
  guide_solves[g] = solves;
  guide_rows[g] = solves * rows;
}

GuideSimulator::GuideSimulator(const Mesh &rest_mesh, const Guides &guides, const DynamicsSettings &settings)
    : state_(std::make_unique<State>()) {
  check_settings(settings);
  State &st = *state_;
  st.settings = settings;
  st.offsets = guides.strands.offsets;
  st.roots = guides.roots;
  const size_t guide_num = guides.size();
  const size_t joint_num = guides.strands.point_count();
  if (guides.strands.strand_count() != guide_num) throw InternalError("dynamics: one root per guide expected");
  for (size_t g = 0; g < guide_num; ++g)
    if (guides.strands.points_in(g) < 2) throw InternalError("dynamics: guide with fewer than 2 points");

  st.root_from.resize(guide_num);
  st.root_to.resize(guide_num);
  st.guide_solves.assign(guide_num, 0);
  st.guide_rows.assign(guide_num, 0);
  st.guide_queries.assign(guide_num, 0);
  st.root_rest.resize(guide_num);
  st.query_closest.assign(joint_num, SurfacePoint{});
  st.rest_closest.assign(joint_num, SurfacePoint{});
  for (auto *a : {&st.rest_local, &st.x, &st.v, &st.gold, &st.query_point, &st.dir, &st.target, &st.velocity_rhs,
                  &st.correction, &st.contact_normal, &st.contact_velocity})
    a->assign(joint_num, Vector3d::Zero());
  for (auto *a : {&st.rest_length, &st.inv_rest_length, &st.mass, &st.inv_mass, &st.stiffness, &st.emitter_margin, &st.tension,
                  &st.query_clearance, &st.rest_clearance, &st.skin_travel, &st.lower, &st.diag, &st.upper, &st.scalar_rhs,
                  &st.contact_friction})
    a->assign(joint_num, 0.0);

  // Stiffness k_i = s(u) * scale * EI_ref / l_i^3 with EI_ref = rho g_ref L^3: a discrete rod of
  // bending stiffness EI whose sag under its own weight does not depend on the joint count (a
  // horizontal guide of stiffness 1 bends about 1/6 rad under gravity). See docs/dynamics.md.
  const double g_ref = settings.gravity.norm() > 0.0f ? double(settings.gravity.norm()) : 981.0;
  const double rho = settings.mass_per_unit;
  std::unique_ptr<MeshQuery> rest_query;
  if (settings.collide_with_emitter) rest_query = std::make_unique<MeshQuery>(rest_mesh);
  for (size_t g = 0; g < guide_num; ++g) {
    const int64_t begin = st.offsets[g], n = st.offsets[g + 1] - begin;
    const FramePose rest_frame = FramePose::from(surface_frame(rest_mesh, st.roots[g]));
    st.root_rest[g] = rest_frame;
    const auto points = guides.strands.points(g);
    const double length = std::max(guides.strands.length(g), 1e-12);
    const double min_segment = 1e-6 * length;
    double arc = 0.0;
    for (int64_t i = 0; i < n; ++i) {
      st.rest_local[begin + i] = rest_frame.rotation.conjugate() * (points[i].cast<double>() - rest_frame.origin);
      if (i > 0) {
        const double l = std::max((points[i] - points[i - 1]).cast<double>().norm(), min_segment);
        st.rest_length[begin + i] = l;
        st.inv_rest_length[begin + i] = 1.0 / l;
        const double u = arc / length;  // the bending joint x_{i-1} along the guide
        st.stiffness[begin + i] =
            i >= 2 ? settings.stiffness.at(float(u)) * settings.stiffness_scale * rho * g_ref * std::pow(length / l, 3.0)
                   : 0.0;
        arc += l;
      }
    }
    for (int64_t i = 0; i < n; ++i) {
      const double l_in = i > 0 ? st.rest_length[begin + i] : 0.0;
      const double l_out = i + 1 < n ? st.rest_length[begin + i + 1] : 0.0;
      st.mass[begin + i] = rho * 0.5 * (l_in + l_out);
      st.inv_mass[begin + i] = i >= 2 ? 1.0 / st.mass[begin + i] : 0.0;
      // Emitter clearance: the margin, or less for a joint groomed closer to the skin; a joint
      // groomed under the skin is left where the groomer put it.
      double margin = -1.0;
      st.rest_closest[begin + i] = st.roots[g];
      if (rest_query && i >= 2) {
        const double d = rest_query->signed_distance(points[i], &st.rest_closest[begin + i]);
        if (d >= 0.0) margin = std::min(double(settings.collision_margin), d);
        // The float distance, less a slack for its rounding at this coordinate magnitude.
        st.rest_clearance[begin + i] = d - 1e-5 * (1.0 + double(points[i].norm()));
      }
      st.emitter_margin[begin + i] = margin;
    }
  }
  st.shapes = SkinShapes(rest_mesh, settings.shapes);
  st.rest_positions = rest_mesh.positions;
  view_ = guides.strands;
}

GuideSimulator::~GuideSimulator() = default;

std::span<const Eigen::Vector3d> GuideSimulator::positions() const { return state_->x; }
std::span<const Eigen::Vector3d> GuideSimulator::velocities() const { return state_->v; }

void GuideSimulator::reset(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns) {
  State &st = *state_;
  if (posed_mesh.vertex_count() != st.rest_positions.size())
    throw InputError("dynamics: the posed mesh has " + std::to_string(posed_mesh.vertex_count()) +
                     " vertices, expected " + std::to_string(st.rest_positions.size()));
  if (!root_turns.empty() && root_turns.size() != st.guide_count())
    throw InternalError("dynamics: one root turn per guide expected");
  st.pose_roots(posed_mesh, root_turns);
  st.root_from = st.root_to;
  const RigidMotion from_rest =
      st.settings.collide_with_emitter ? fit_rigid_motion(st.rest_positions, posed_mesh.positions) : RigidMotion{};
#pragma omp parallel for schedule(dynamic, 64) if (st.guide_count() >= kParallelGuides)
  for (int64_t g = 0; g < int64_t(st.guide_count()); ++g) st.reset_guide(size_t(g), from_rest);
  st.mesh_to = posed_mesh;
  st.mesh_sub = posed_mesh;
  st.sub_start_positions = posed_mesh.positions;
  st.query.reset();
  st.query_once.reset();
  st.shapes.frames(posed_mesh, st.shape_frames_to);
  st.posed = true;
  time_ = 0.0;
  st.copy_positions(view_.positions);
}

void GuideSimulator::step_frame(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns) {
  State &st = *state_;
  if (!st.posed) reset(posed_mesh, root_turns);
  if (!root_turns.empty() && root_turns.size() != st.guide_count())
    throw InternalError("dynamics: one root turn per guide expected");
  if (posed_mesh.vertex_count() != st.mesh_to.vertex_count())
    throw InputError("dynamics: the posed mesh has " + std::to_string(posed_mesh.vertex_count()) +
                     " vertices, expected " + std::to_string(st.mesh_to.vertex_count()));
  std::swap(st.mesh_from, st.mesh_to);
  st.mesh_to = posed_mesh;
  st.root_from.swap(st.root_to);  // root_to is posed by each guide in its first substep
  st.shape_frames_from.swap(st.shape_frames_to);
  st.shapes.frames(posed_mesh, st.shape_frames_to);

  const int substeps = st.settings.substeps;
  const double frame_time = 1.0 / st.settings.fps;
  const double h = frame_time / substeps;
  for (int s = 0; s < substeps; ++s) {
    const double s0 = double(s) / substeps, s1 = double(s + 1) / substeps;
    st.shapes.pose(st.shape_frames_from, st.shape_frames_to, s0, st.shapes_start);
    st.shapes.pose(st.shape_frames_from, st.shape_frames_to, s1, st.shapes_end);
    if (st.settings.collide_with_emitter) {
      // The emitter at the end of the substep, vertices lerped between the two poses.
      double move2 = 0.0;
      for (size_t p = 0; p < st.mesh_sub.positions.size(); ++p) {
        st.sub_start_positions[p] = st.mesh_sub.positions[p];
        st.mesh_sub.positions[p] = st.mesh_from.positions[p] + float(s1) * (st.mesh_to.positions[p] - st.mesh_from.positions[p]);
        move2 = std::max(move2, double((st.mesh_sub.positions[p] - st.sub_start_positions[p]).squaredNorm()));
      }
      st.skin_motion = move2 > 0.0 ? fit_rigid_motion(st.sub_start_positions, st.mesh_sub.positions) : RigidMotion{};
      // A still emitter (a held pose, a pre-roll) keeps its tree.
      if (move2 > 0.0 || !st.query_once) {
        st.query.reset();
        st.query_once = std::make_unique<std::once_flag>();
      }
    }
    const double time_end = time_ + (s + 1) * h;
#pragma omp parallel for schedule(dynamic, 64) if (st.guide_count() >= kParallelGuides)
    for (int64_t g = 0; g < int64_t(st.guide_count()); ++g) {
      // The per-frame work of a guide rides in the substeps' parallel loop (one parallel region
      // per substep): its root frame on the new pose first, its float view last.
      if (s == 0)
        st.root_to[size_t(g)] =
            root_frame(st.mesh_to, st.roots[size_t(g)], root_turns, size_t(g), st.rest_local[size_t(st.offsets[size_t(g)])]);
      st.substep_guide(size_t(g), s0, s1, h, time_end);
      if (s + 1 == substeps)
        for (int64_t p = st.offsets[size_t(g)]; p < st.offsets[size_t(g) + 1]; ++p)
          view_.positions[size_t(p)] = st.x[size_t(p)].cast<float>();
    }
    if (st.query_error) std::rethrow_exception(std::exchange(st.query_error, nullptr));
    ++work_.substeps;
    for (size_t g = 0; g < st.guide_count(); ++g) {
      work_.tridiagonal_solves += st.guide_solves[g];
      work_.tridiagonal_rows += st.guide_rows[g];
      work_.emitter_queries += st.guide_queries[g];
      work_.joint_updates += std::max<int64_t>(0, st.offsets[g + 1] - st.offsets[g] - 2);
    }
  }
  time_ += frame_time;
}

}  // namespace plume::dynamics
