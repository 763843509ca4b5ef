// Writes the bird of grooms/bird/: its body (body, neck, head, beak, folded wings) as an OBJ with
// UVs and tract face groups, the OBJ sequence of it moving (the left wing opening and folding, the
// neck bending 90 degrees to the side and back, breathing +-10% of the body's volume), and the stems
// of its guide feathers. Standalone (the C++ standard library only), deterministic: a test checks
// that it reproduces the files kept in the repository byte for byte.
//
//   make_bird OUTPUT_FOLDER      writes bird.obj, stems.obj and anim/bird.0001.obj .. bird.0048.obj
//
// Units are centimetres; +y is up, the bird faces +z, its left is +x.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kFrames = 48;

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
  Vec3 operator+(const Vec3 &o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3 operator-(const Vec3 &o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  double dot(const Vec3 &o) const { return x * o.x + y * o.y + z * o.z; }
  Vec3 cross(const Vec3 &o) const { return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x}; }
  double norm() const { return std::sqrt(dot(*this)); }
  Vec3 normalized() const { return *this * (1.0 / norm()); }
};

double lerp(double a, double b, double t) { return a + (b - a) * t; }
double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

/// A piecewise-linear profile: value at parameter s from sorted (s, value) keys.
double profile(const std::vector<std::array<double, 2>> &keys, double s) {
  if (s <= keys.front()[0]) return keys.front()[1];
  for (size_t i = 1; i < keys.size(); ++i)
    if (s <= keys[i][0]) return lerp(keys[i - 1][1], keys[i][1], (s - keys[i - 1][0]) / (keys[i][0] - keys[i - 1][0]));
  return keys.back()[1];
}

/// A Catmull-Rom curve through points, parametrised by normalised arc length (tabulated).
class Curve {
 public:
  explicit Curve(std::vector<Vec3> points) : points_(std::move(points)) {
    const int samples = 2000;
    double length = 0.0;
    Vec3 previous = raw(0.0);
    table_.push_back({0.0, 0.0});
    for (int i = 1; i <= samples; ++i) {
      const double u = double(i) / samples;
      const Vec3 p = raw(u);
      length += (p - previous).norm();
      previous = p;
      table_.push_back({u, length});
    }
    for (auto &entry : table_) entry[1] /= length;
    length_ = length;
  }
  /// The point at normalised arc length s in [0, 1].
  Vec3 at(double s) const { return raw(parameter(s)); }
  Vec3 tangent(double s) const {
    const double h = 1e-4;
    return (at(std::min(1.0, s + h)) - at(std::max(0.0, s - h))).normalized();
  }
  double length() const { return length_; }

 private:
  Vec3 raw(double u) const {
    const int segments = int(points_.size()) - 1;
    const double x = std::clamp(u, 0.0, 1.0) * segments;
    const int i = std::min(int(x), segments - 1);
    const double t = x - i;
    const Vec3 &p1 = points_[size_t(i)], &p2 = points_[size_t(i + 1)];
    const Vec3 p0 = i > 0 ? points_[size_t(i - 1)] : p1 * 2.0 - p2;
    const Vec3 p3 = i + 2 < int(points_.size()) ? points_[size_t(i + 2)] : p2 * 2.0 - p1;
    const double t2 = t * t, t3 = t2 * t;
    return (p1 * 2.0 + (p2 - p0) * t + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * t2 + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * t3) * 0.5;
  }
  double parameter(double s) const {
    s = std::clamp(s, 0.0, 1.0);
    size_t hi = 1;
    while (hi + 1 < table_.size() && table_[hi][1] < s) ++hi;
    const auto &a = table_[hi - 1], &b = table_[hi];
    return lerp(a[0], b[0], b[1] > a[1] ? (s - a[1]) / (b[1] - a[1]) : 0.0);
  }
  std::vector<Vec3> points_;
  std::vector<std::array<double, 2>> table_;
  double length_ = 0.0;
};

struct Face {
  std::vector<int> v, vt;
  int group = 0;
};

struct Mesh {
  std::vector<Vec3> v;
  std::vector<std::array<double, 2>> vt;
  std::vector<Face> faces;
  std::vector<std::string> groups;
  int group(const std::string &name) {
    for (size_t i = 0; i < groups.size(); ++i)
      if (groups[i] == name) return int(i);
    groups.push_back(name);
    return int(groups.size()) - 1;
  }
};

/// What each vertex is, for the motions: which part it belongs to and where on it.
struct VertexInfo {
  enum class Part { body, left_wing, right_wing } part = Part::body;
  double s = 0.0;  // body: normalised arc length along the spine; wings: along the span
};

// ---------------------------------------------------------------------------------------------
// The body: a tube around a spine from the tail's tip to the beak's tip, closed at both ends.

const Curve &spine() {
  static const Curve curve({{0, 6.0, -17.0}, {0, 6.3, -11.0}, {0, 6.0, -3.0}, {0, 7.6, 4.0}, {0, 11.0, 7.2},
                            {0, 14.2, 8.6}, {0, 16.0, 10.4}, {0, 16.4, 12.8}, {0, 15.8, 15.8}});
  return curve;
}

// Cross-section half-widths (x) and half-heights (y) along the spine.
const std::vector<std::array<double, 2>> kWidth = {{0.0, 0.4},  {0.06, 1.8}, {0.16, 3.2}, {0.34, 4.9}, {0.48, 4.6},
                                                   {0.58, 3.2}, {0.64, 2.3}, {0.74, 1.9}, {0.80, 2.4}, {0.86, 2.7},
                                                   {0.92, 2.0}, {0.955, 0.9}, {1.0, 0.25}};
const std::vector<std::array<double, 2>> kHeight = {{0.0, 0.3},  {0.06, 0.7}, {0.16, 2.8}, {0.34, 5.0}, {0.48, 5.2},
                                                    {0.58, 3.6}, {0.64, 2.4}, {0.74, 1.9}, {0.80, 2.5}, {0.86, 2.9},
                                                    {0.92, 2.1}, {0.955, 0.7}, {1.0, 0.2}};
constexpr int kRings = 40;     // rings between the two poles
constexpr int kAround = 36;    // vertices per ring

/// The ring frame at s: side (x), up, tangent.
void ring_frame(double s, Vec3 &r_side, Vec3 &r_up, Vec3 &r_tangent) {
  r_tangent = spine().tangent(s);
  r_side = {1.0, 0.0, 0.0};
  r_up = r_tangent.cross(r_side).normalized();
}

double ring_s(int i) { return double(i + 1) / double(kRings + 1); }

std::string body_group(double s, double angle) {
  const double up = std::sin(angle), side = std::abs(std::cos(angle));
  // Tail feathers fan out from the tail's top; down covers its underside.
  // The tip of the tail, its triangles small around the pole, stays bare: a frame from a triangle a
  // millimetre across would turn with the rounding of its corners' coordinates.
  if (s < 0.07) return "tail_tip";
  if (s < 0.13) return up > -0.2 ? "tail" : "belly";
  if (s >= 0.95) return "beak";
  if (s >= 0.83) return "head";
  if (s >= 0.62) return "neck";
  if (up > 0.25) return "back";
  // The flanks under the folded wings: bare skin (an apterium), which the wing covers.
  if (side > 0.55 && s > 0.17 && s < 0.56) return "flank";
  if (up < -0.35 && s < 0.5) return "belly";
  return "breast";
}

void add_body(Mesh &mesh, std::vector<VertexInfo> &info) {
  const int first = int(mesh.v.size());
  auto vertex = [&](int ring, int j) { return first + 1 + ring * kAround + (j % kAround); };
  mesh.v.push_back(spine().at(0.0));
  info.push_back({VertexInfo::Part::body, 0.0});
  for (int i = 0; i < kRings; ++i) {
    const double s = ring_s(i);
    Vec3 side, up, tangent;
    ring_frame(s, side, up, tangent);
    const Vec3 centre = spine().at(s);
    for (int j = 0; j < kAround; ++j) {
      const double a = 2.0 * kPi * j / kAround;
      mesh.v.push_back(centre + side * (profile(kWidth, s) * std::cos(a)) + up * (profile(kHeight, s) * std::sin(a)));
      info.push_back({VertexInfo::Part::body, s});
    }
  }
  mesh.v.push_back(spine().at(1.0));
  info.push_back({VertexInfo::Part::body, 1.0});
  const int last = int(mesh.v.size()) - 1;
  // UVs: u around (the seam at angle 0, duplicated), v along the spine; the poles at v = 0 and 1.
  const int first_uv = int(mesh.vt.size());
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j <= kAround; ++j) mesh.vt.push_back({double(j) / kAround, 0.5 * ring_s(i)});
  auto uv = [&](int ring, int j) { return first_uv + ring * (kAround + 1) + j; };
  const int pole_uv = int(mesh.vt.size());
  for (int j = 0; j < kAround; ++j) mesh.vt.push_back({(j + 0.5) / kAround, 0.0});
  for (int j = 0; j < kAround; ++j) mesh.vt.push_back({(j + 0.5) / kAround, 0.5});
  // Faces wind counter-clockwise seen from outside.
  for (int j = 0; j < kAround; ++j) {
    Face f;
    f.v = {first, vertex(0, j + 1), vertex(0, j)};
    f.vt = {pole_uv + j, uv(0, j + 1), uv(0, j)};
    f.group = mesh.group(body_group(0.0, 2.0 * kPi * (j + 0.5) / kAround));
    mesh.faces.push_back(f);
  }
  for (int i = 0; i + 1 < kRings; ++i)
    for (int j = 0; j < kAround; ++j) {
      Face f;
      f.v = {vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1), vertex(i + 1, j)};
      f.vt = {uv(i, j), uv(i, j + 1), uv(i + 1, j + 1), uv(i + 1, j)};
      f.group = mesh.group(body_group(0.5 * (ring_s(i) + ring_s(i + 1)), 2.0 * kPi * (j + 0.5) / kAround));
      mesh.faces.push_back(f);
    }
  for (int j = 0; j < kAround; ++j) {
    Face f;
    f.v = {vertex(kRings - 1, j), vertex(kRings - 1, j + 1), last};
    f.vt = {uv(kRings - 1, j), uv(kRings - 1, j + 1), pole_uv + kAround + j};
    f.group = mesh.group("beak");
    mesh.faces.push_back(f);
  }
}

// ---------------------------------------------------------------------------------------------
// The wings: thin closed shells, folded along the body's sides (span toward the tail, chord
// vertical, leading edge up), their roots inside the shoulders.

constexpr int kSpan = 14;     // rings between the root and tip poles
constexpr int kChord = 16;    // vertices per ring

/// The wing's centre line at span parameter v (left wing: x > 0; the right mirrors it).
Vec3 wing_centre(double v) {
  static const Curve curve({{3.4, 9.6, 3.0}, {5.9, 9.6, 1.6}, {6.4, 9.3, -3.0}, {6.5, 8.6, -8.0}, {6.6, 8.0, -12.5}});
  return curve.at(v);
}
const std::vector<std::array<double, 2>> kChordLength = {{0.0, 1.6}, {0.15, 5.0}, {0.5, 4.6}, {0.85, 3.0}, {1.0, 0.6}};
const std::vector<std::array<double, 2>> kThickness = {{0.0, 1.0}, {0.15, 0.9}, {0.5, 0.5}, {1.0, 0.15}};

std::string wing_group(bool left, double v, double angle) {
  const std::string side = left ? "left" : "right";
  const double out = std::cos(angle), up = std::sin(angle);
  if (v < 0.16) return "wing_root";
  // The outer face: coverts above, flight feathers along its lower (trailing) part, lying in the
  // wing's plane; the inner face, against the body, stays bare.
  if (out > 0.2) return up < -0.3 ? side + "_flight" : side + "_wing";
  return "wing_under";
}

void add_wing(Mesh &mesh, std::vector<VertexInfo> &info, bool left) {
  const double mirror = left ? 1.0 : -1.0;
  const VertexInfo::Part part = left ? VertexInfo::Part::left_wing : VertexInfo::Part::right_wing;
  auto v_of = [](int ring) { return double(ring + 1) / double(kSpan + 1); };
  auto place = [&](const Vec3 &p) { return Vec3{mirror * p.x, p.y, p.z}; };
  const int first = int(mesh.v.size());
  auto vertex = [&](int ring, int j) { return first + 1 + ring * kChord + (j % kChord); };
  mesh.v.push_back(place(wing_centre(0.0)));
  info.push_back({part, 0.0});
  for (int i = 0; i < kSpan; ++i) {
    const double v = v_of(i);
    const Vec3 c = wing_centre(v);
    for (int j = 0; j < kChord; ++j) {
      const double a = 2.0 * kPi * j / kChord;
      // Thickness across x, chord along y (with a slight backward sweep of the leading edge).
      const Vec3 p = c + Vec3{0.5 * profile(kThickness, v) * std::cos(a), 0.5 * profile(kChordLength, v) * std::sin(a),
                              -0.15 * profile(kChordLength, v) * std::sin(a)};
      mesh.v.push_back(place(p));
      info.push_back({part, v});
    }
  }
  mesh.v.push_back(place(wing_centre(1.0)));
  info.push_back({part, 1.0});
  const int last = int(mesh.v.size()) - 1;
  const int first_uv = int(mesh.vt.size());
  const double u0 = left ? 0.0 : 0.5;
  for (int i = 0; i < kSpan; ++i)
    for (int j = 0; j <= kChord; ++j) mesh.vt.push_back({u0 + 0.5 * j / kChord, 0.5 + 0.5 * v_of(i)});
  auto uv = [&](int ring, int j) { return first_uv + ring * (kChord + 1) + j; };
  const int pole_uv = int(mesh.vt.size());
  for (int j = 0; j < kChord; ++j) mesh.vt.push_back({u0 + 0.5 * (j + 0.5) / kChord, 0.5});
  for (int j = 0; j < kChord; ++j) mesh.vt.push_back({u0 + 0.5 * (j + 0.5) / kChord, 1.0});
  // Outward winding: the right wing is mirrored, so its faces run the other way round.
  auto add = [&](std::vector<int> vs, std::vector<int> ts, int group) {
    if (!left) {
      std::reverse(vs.begin(), vs.end());
      std::reverse(ts.begin(), ts.end());
    }
    mesh.faces.push_back({vs, ts, group});
  };
  for (int j = 0; j < kChord; ++j)
    add({first, vertex(0, j), vertex(0, j + 1)}, {pole_uv + j, uv(0, j), uv(0, j + 1)}, mesh.group("wing_root"));
  for (int i = 0; i + 1 < kSpan; ++i)
    for (int j = 0; j < kChord; ++j)
      add({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)},
          {uv(i, j), uv(i + 1, j), uv(i + 1, j + 1), uv(i, j + 1)},
          mesh.group(wing_group(left, 0.5 * (v_of(i) + v_of(i + 1)), 2.0 * kPi * (j + 0.5) / kChord)));
  for (int j = 0; j < kChord; ++j)
    add({vertex(kSpan - 1, j), last, vertex(kSpan - 1, j + 1)}, {uv(kSpan - 1, j), pole_uv + kChord + j, uv(kSpan - 1, j + 1)},
        mesh.group(wing_group(left, 1.0, 2.0 * kPi * (j + 0.5) / kChord)));
}

// ---------------------------------------------------------------------------------------------
// Motions. Frame f of 1 .. 48 (24 per second); frame 1 is the rest pose.

/// Breathing: the torso's cross-sections scaled about the spine by a factor that peaks at the body's
/// middle and fades to 1 at the tail and the neck.
double torso_weight(double s) { return smoothstep((s - 0.10) / 0.15) * (1.0 - smoothstep((s - 0.50) / 0.14)); }

/// The left wing's opening, radians about the vertical axis through the shoulder.
double wing_angle(int frame) {
  const double t = frame - 1.0;
  if (t <= 14.0) return 1.45 * smoothstep(t / 14.0);
  if (t <= 22.0) return 1.45;
  return 1.45 * (1.0 - smoothstep((t - 22.0) / 16.0));
}

/// The neck's bend to the bird's right, radians: 90 degrees half way (89.9 at frames 24 and 25), back by frame 48.
double neck_angle(int frame) {
  const double t = (frame - 1.0) / (kFrames - 1.0);
  const double s = std::sin(kPi * t);
  return 0.5 * kPi * s * s;
}

/// Signed volume enclosed by the faces of `part` (divergence theorem over fan triangles).
double volume_of(const Mesh &mesh, const std::vector<Vec3> &p, const std::vector<VertexInfo> &info, VertexInfo::Part part) {
  double volume = 0.0;
  for (const Face &f : mesh.faces) {
    if (info[size_t(f.v[0])].part != part) continue;
    for (size_t k = 1; k + 1 < f.v.size(); ++k)
      volume += p[size_t(f.v[0])].dot(p[size_t(f.v[k])].cross(p[size_t(f.v[k + 1])])) / 6.0;
  }
  return volume;
}

std::vector<Vec3> pose(const Mesh &mesh, const std::vector<VertexInfo> &info, int frame) {
  std::vector<Vec3> p = mesh.v;
  // Breathing: +-10% of the body's volume, once a second. The scale of the torso is found by
  // bisection so that the closed body's volume is exactly the wanted one.
  const double rest_volume = volume_of(mesh, mesh.v, info, VertexInfo::Part::body);
  const double wanted = rest_volume * (1.0 + 0.1 * std::sin(2.0 * kPi * (frame - 1.0) / 24.0));
  std::vector<Vec3> centres(p.size());
  for (size_t i = 0; i < p.size(); ++i)
    if (info[i].part == VertexInfo::Part::body) centres[i] = spine().at(info[i].s);
  auto breathe = [&](double scale) {
    std::vector<Vec3> q = mesh.v;
    for (size_t i = 0; i < q.size(); ++i) {
      if (info[i].part != VertexInfo::Part::body) continue;
      q[i] = centres[i] + (q[i] - centres[i]) * (1.0 + (scale - 1.0) * torso_weight(info[i].s));
    }
    return q;
  };
  double lo = 0.5, hi = 1.5, scale = 1.0;
  if (frame != 1) {
    for (int iteration = 0; iteration < 60; ++iteration) {
      scale = 0.5 * (lo + hi);
      (volume_of(mesh, breathe(scale), info, VertexInfo::Part::body) < wanted ? lo : hi) = scale;
    }
    p = breathe(scale);
  }
  // The wings ride on the breathing flanks: each moves with its shoulder's point of the torso.
  const double shoulder_s = 0.50;
  const double flank_shift = profile(kWidth, shoulder_s) * (scale - 1.0) * torso_weight(shoulder_s);
  // The left wing opens: turned about the vertical axis through its root, and raised a little.
  const double opening = wing_angle(frame);
  const Vec3 root = wing_centre(0.0);
  for (size_t i = 0; i < p.size(); ++i) {
    if (info[i].part == VertexInfo::Part::body) continue;
    const bool left = info[i].part == VertexInfo::Part::left_wing;
    Vec3 q = p[i] + Vec3{(left ? 1.0 : -1.0) * flank_shift, 0.0, 0.0};
    if (left && opening > 0.0) {
      const Vec3 d = q - root;
      // About y (the wing swings out) then about the span's new direction's normal (it rises).
      const double c = std::cos(opening), s = std::sin(opening);
      Vec3 e{c * d.x - s * d.z, d.y, s * d.x + c * d.z};
      const double lift = 0.25 * opening;
      const double cl = std::cos(lift), sl = std::sin(lift);
      e = Vec3{cl * e.x - sl * e.y, sl * e.x + cl * e.y, e.z};
      q = root + e;
    }
    p[i] = q;
  }
  // The neck bends to the bird's right (-x) about the z axis (Barr's bend): from the neck's base
  // (spine parameter 0.62) over the next 0.2 of the spine; the head turns with the bend's end.
  const double bend = neck_angle(frame);
  if (bend > 0.0) {
    const double s0 = 0.60, s1 = 0.80;
    const Vec3 base = spine().at(s0);
    const Vec3 axis_u = (spine().at(s1) - base).normalized();  // along the neck
    const Vec3 axis_b{-1.0, 0.0, 0.0};                          // toward the bend
    const double length = (spine().at(s1) - base).norm();
    const double radius = length / bend;
    for (size_t i = 0; i < p.size(); ++i) {
      if (info[i].part != VertexInfo::Part::body || info[i].s < s0) continue;
      const Vec3 d = p[i] - base;
      const double y = d.dot(axis_u), x = d.dot(axis_b);
      const Vec3 rest_of = d - axis_u * y - axis_b * x;
      if (y <= 0.0) continue;
      // radius - (radius - x) cos phi and (radius - x) sin phi, written to stay exact as the bend
      // (and phi) goes to 0 and the radius to infinity.
      const double phi = std::min(y, length) / radius;
      const double half = std::sin(0.5 * phi);
      double bx = 2.0 * radius * half * half + x * std::cos(phi), by = (radius - x) * std::sin(phi);
      if (y > length) {
        bx += (y - length) * std::sin(bend);
        by += (y - length) * std::cos(bend);
      }
      p[i] = base + axis_b * bx + axis_u * by + rest_of;
    }
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// Guide stems: straight, lifted off the skin, laid along the body toward the tail (along the span
// on the wings).

struct Stem {
  std::vector<Vec3> points;
};

/// `p` moved out of the body to at least `clearance` outside it, measured on the body's elliptic
/// cross-section at the spine point nearest to p (where the body is a tube, the surface itself).
Vec3 outside_body(const Vec3 &p, double clearance) {
  static const std::vector<Vec3> centres = [] {
    std::vector<Vec3> c;
    for (int k = 0; k <= 400; ++k) c.push_back(spine().at(k / 400.0));
    return c;
  }();
  size_t nearest = 0;
  for (size_t k = 1; k < centres.size(); ++k)
    if ((centres[k] - p).norm() < (centres[nearest] - p).norm()) nearest = k;
  const double s = nearest / 400.0;
  Vec3 side, up, tangent;
  ring_frame(s, side, up, tangent);
  const Vec3 d = p - centres[nearest];
  const double x = d.dot(side), y = d.dot(up);
  const double rx = profile(kWidth, s), ry = profile(kHeight, s);
  const double rho = std::sqrt((x / rx) * (x / rx) + (y / ry) * (y / ry));
  const double wanted = 1.0 + clearance / std::min(rx, ry);
  if (rho >= wanted || rho < 1e-9) return p;
  const double scale = wanted / rho;
  return centres[nearest] + tangent * d.dot(tangent) + side * (x * scale) + up * (y * scale);
}

Vec3 face_normal(const Mesh &mesh, const Face &f) {
  const Vec3 &a = mesh.v[size_t(f.v[0])], &b = mesh.v[size_t(f.v[1])], &c = mesh.v[size_t(f.v[2])];
  return (b - a).cross(c - a).normalized();
}

constexpr int kStemPoints = 6;

std::vector<Stem> make_stems(const Mesh &mesh) {
  std::vector<Stem> stems;
  // A stem leaves the skin at `lift` along the flow; on the body it then follows the surface, kept
  // outside it by a clearance that grows along the stem, as a groomer combs stems over a body.
  auto lay = [&](const Vec3 &root, const Vec3 &normal, const Vec3 &flow, double lift, double length, bool body) {
    const Vec3 along = (flow - normal * flow.dot(normal)).normalized();
    const Vec3 direction = (along * std::cos(lift) + normal * std::sin(lift)).normalized();
    Stem stem;
    stem.points.push_back(root);
    Vec3 p = root;
    for (int k = 1; k < kStemPoints; ++k) {
      const double step = length / (kStemPoints - 1);
      Vec3 next = p + (k == 1 ? direction : (p - stem.points[size_t(k - 2)]).normalized()) * step;
      if (body && k > 1) next = outside_body(next, std::min(0.6, 0.12 * step * k));
      // Keep the step length.
      next = p + (next - p).normalized() * step;
      stem.points.push_back(next);
      p = next;
    }
    stems.push_back(stem);
  };
  // Body: every other ring, every third vertex around, on feathered tracts.
  for (int i = 1; i < kRings; i += 2) {
    const double s = ring_s(i);
    for (int j = 0; j < kAround; j += 3) {
      const double a = 2.0 * kPi * (j + 0.5) / kAround;
      const std::string group = body_group(s, a);
      if (group == "beak" || group == "flank") continue;
      // The face of ring i - 1 .. i at this angle: its centre and normal.
      const Face &f = mesh.faces[size_t(kAround + (i - 1) * kAround + j)];
      Vec3 centre;
      for (int v : f.v) centre = centre + mesh.v[size_t(v)] * (1.0 / f.v.size());
      const Vec3 normal = face_normal(mesh, f);
      const double length = group == "tail" ? 13.0 : group == "head" ? 1.6 : group == "neck" ? 2.4 : 4.2;
      const double lift = group == "tail" ? 0.10 : 0.22;
      lay(centre, normal, spine().tangent(s) * -1.0, lift, length, true);
    }
  }
  // Wings: on the outer side and along the trailing edge, toward the tip.
  for (const Face &f : mesh.faces) {
    const std::string &group = mesh.groups[size_t(f.group)];
    const bool edge = group == "left_flight" || group == "right_flight";
    const bool outer = group == "left_wing" || group == "right_wing";
    if (!edge && !outer) continue;
    const int index = int(&f - mesh.faces.data());
    if (index % (edge ? 2 : 5) != 0) continue;
    Vec3 centre;
    for (int v : f.v) centre = centre + mesh.v[size_t(v)] * (1.0 / f.v.size());
    lay(centre, face_normal(mesh, f), Vec3{0.0, -0.15, -1.0}, edge ? 0.06 : 0.15, edge ? 12.0 : 4.5, false);
  }
  return stems;
}

// ---------------------------------------------------------------------------------------------
// Writing.

std::string format(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", v);
  std::string s = text;
  if (s == "-0.0000") s = "0.0000";
  return s;
}

void write_file(const std::filesystem::path &path, const std::string &text) {
  std::FILE *file = std::fopen(path.string().c_str(), "wb");
  if (!file || std::fwrite(text.data(), 1, text.size(), file) != text.size() || std::fclose(file) != 0) {
    std::fprintf(stderr, "make_bird: cannot write %s\n", path.string().c_str());
    std::exit(1);
  }
}

std::string mesh_text(const Mesh &mesh, const std::vector<Vec3> &positions, bool rest, int frame) {
  std::string out;
  if (rest) {
    out += "# The bird of grooms/bird/ at rest (written by make_bird): " + std::to_string(mesh.v.size()) +
           " vertices, " + std::to_string(mesh.faces.size()) + " faces; centimetres, +y up, facing +z.\n";
  } else {
    out += "# The bird of grooms/bird/, frame " + std::to_string(frame) + " (written by make_bird).\n";
  }
  for (const Vec3 &p : positions) out += "v " + format(p.x) + " " + format(p.y) + " " + format(p.z) + "\n";
  if (rest)
    for (const auto &t : mesh.vt) out += "vt " + format(t[0]) + " " + format(t[1]) + "\n";
  int current = -1;
  for (const Face &f : mesh.faces) {
    if (rest && f.group != current) {
      current = f.group;
      out += "g " + mesh.groups[size_t(f.group)] + "\n";
    }
    out += "f";
    for (size_t k = 0; k < f.v.size(); ++k) {
      out += ' ';
      out += std::to_string(f.v[k] + 1);
      if (rest) {
        out += '/';
        out += std::to_string(f.vt[k] + 1);
      }
    }
    out += "\n";
  }
  return out;
}

}  // namespace

/// Every body face must face away from the spine: a tube whose rings overlap where the spine bends
/// more tightly than the tube is thick would fold inside out there (inverted normals).
void check_body_faces(const Mesh &mesh, const std::vector<VertexInfo> &info) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face &face = mesh.faces[f];
    if (info[size_t(face.v[0])].part != VertexInfo::Part::body) continue;
    Vec3 centre;
    double s = 0.0;
    for (int v : face.v) {
      centre = centre + mesh.v[size_t(v)] * (1.0 / face.v.size());
      s += info[size_t(v)].s / face.v.size();
    }
    const Vec3 normal = (mesh.v[size_t(face.v[1])] - mesh.v[size_t(face.v[0])])
                            .cross(mesh.v[size_t(face.v[2])] - mesh.v[size_t(face.v[0])]);
    if (s > 0.02 && s < 0.98 && normal.dot(centre - spine().at(s)) <= 0.0) {
      std::fprintf(stderr, "make_bird: body face %zu (spine %.3f) faces the spine: the tube folds there\n", f, s);
      std::exit(1);
    }
  }
}

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_bird OUTPUT_FOLDER\n");
    return 2;
  }
  const std::filesystem::path folder = argv[1];
  std::filesystem::create_directories(folder / "anim");

  Mesh mesh;
  std::vector<VertexInfo> info;
  add_body(mesh, info);
  add_wing(mesh, info, true);
  add_wing(mesh, info, false);
  check_body_faces(mesh, info);
  write_file(folder / "bird.obj", mesh_text(mesh, mesh.v, true, 1));

  std::string stems_text = "# Guide feather stems of grooms/bird/ (written by make_bird): one polyline each.\n";
  const std::vector<Stem> stems = make_stems(mesh);
  for (const Stem &stem : stems)
    for (const Vec3 &p : stem.points) stems_text += "v " + format(p.x) + " " + format(p.y) + " " + format(p.z) + "\n";
  for (size_t g = 0; g < stems.size(); ++g)
    for (int k = 0; k + 1 < kStemPoints; ++k) {
      const size_t first = g * kStemPoints + size_t(k) + 1;
      stems_text += "l " + std::to_string(first) + " " + std::to_string(first + 1) + "\n";
    }
  write_file(folder / "stems.obj", stems_text);

  for (int frame = 1; frame <= kFrames; ++frame) {
    char name[32];
    std::snprintf(name, sizeof name, "bird.%04d.obj", frame);
    write_file(folder / "anim" / name, mesh_text(mesh, pose(mesh, info, frame), false, frame));
  }
  std::printf("make_bird: %zu vertices, %zu faces, %zu stems, %d frames in %s\n", mesh.v.size(), mesh.faces.size(),
              stems.size(), kFrames, folder.string().c_str());
  return 0;
}
