// The bird's OBJ sequence (grooms/bird/anim) does what its README says, measured on the files alone:
// the body breathes +-10% of its volume, the neck bends 90 degrees (the beak turns with it) and back,
// and the left wing opens and folds back while the right one stays.
#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <Eigen/SVD>

#include "groom/mesh.h"
#include "io/obj_mesh.h"

using namespace plume;

namespace {

const std::string kBird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";

/// Frame `frame` of the sequence, on the rest mesh's faces and groups.
Mesh frame_mesh(int frame, const Mesh &rest) {
  char name[32];
  std::snprintf(name, sizeof name, "anim/bird.%04d.obj", frame);
  return io::read_obj_pose(kBird + name, rest);
}

/// Per vertex: its connected piece of the mesh (the body and each wing are closed shells of their own).
std::vector<int> pieces(const Mesh &mesh) {
  std::vector<int> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[size_t(v)] != v) v = parent[size_t(v)] = parent[size_t(parent[size_t(v)])];
    return v;
  };
  for (const Eigen::Vector3i &t : mesh.triangles)
    for (int k = 1; k < 3; ++k) parent[size_t(root(t[k]))] = root(t[0]);
  std::vector<int> piece(mesh.positions.size());
  for (size_t v = 0; v < piece.size(); ++v) piece[v] = root(int(v));
  return piece;
}

/// The volume the triangles of `piece` enclose (divergence theorem), in double.
double volume(const Mesh &mesh, const std::vector<int> &piece_of, int piece) {
  double v = 0.0;
  for (const Eigen::Vector3i &t : mesh.triangles) {
    if (piece_of[size_t(t[0])] != piece) continue;
    const Eigen::Vector3d a = mesh.positions[size_t(t[0])].cast<double>(), b = mesh.positions[size_t(t[1])].cast<double>(),
                          c = mesh.positions[size_t(t[2])].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

/// The mean of the vertices of the faces of group `name`.
Eigen::Vector3d group_centre(const Mesh &mesh, const std::string &name) {
  const int group = mesh.group_index(name);
  REQUIRE(group >= 0);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    if (mesh.triangle_groups[f] == group)
      for (int k = 0; k < 3; ++k, ++count) sum += mesh.positions[size_t(mesh.triangles[f][k])].cast<double>();
  return sum / double(std::max(count, 1));
}

/// Degrees of the rotation that best carries the vertices of groups `names` from `a` to `b` (Kabsch).
double turn_degrees(const Mesh &a, const Mesh &b, const std::vector<std::string> &names) {
  std::vector<int> used(a.positions.size(), 0);
  for (const std::string &name : names) {
    const int group = a.group_index(name);
    REQUIRE(group >= 0);
    for (size_t f = 0; f < a.triangles.size(); ++f)
      if (a.triangle_groups[f] == group)
        for (int k = 0; k < 3; ++k) used[size_t(a.triangles[f][k])] = 1;
  }
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) {
      ca += a.positions[v].cast<double>();
      cb += b.positions[v].cast<double>();
      ++count;
    }
  ca /= double(count);
  cb /= double(count);
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) h += (a.positions[v].cast<double>() - ca) * (b.positions[v].cast<double>() - cb).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixV() * svd.matrixU().transpose();
  if (r.determinant() < 0.0) {
    Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
    flip(2, 2) = -1.0;
    r = svd.matrixV() * flip * svd.matrixU().transpose();
  }
  return std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
}


}  // namespace

TEST_CASE("the bird breathes +-10% of its body's volume, bends its neck 90 degrees and opens a wing", "[feathers]") {
  const Mesh rest = io::read_obj_mesh(kBird + "bird.obj");
  const std::vector<int> piece_of = pieces(rest);
  // The body is the piece holding the beak.
  const int beak = rest.group_index("beak");
  REQUIRE(beak >= 0);
  int body = -1;
  for (size_t f = 0; f < rest.triangles.size() && body < 0; ++f)
    if (rest.triangle_groups[f] == beak) body = piece_of[size_t(rest.triangles[f][0])];
  const double rest_volume = volume(rest, piece_of, body);
  REQUIRE(rest_volume > 0.0);
  // How far the head (and beak) turned from rest.
  const auto head_turn = [&](const Mesh &m) { return turn_degrees(rest, m, {"head", "beak"}); };
  const Eigen::Vector3d rest_left = group_centre(rest, "left_flight"), rest_right = group_centre(rest, "right_flight");
  const double size = (group_centre(rest, "beak") - group_centre(rest, "tail")).norm();

  double smallest = 2.0, largest = 0.0, most_bent = 0.0, widest = 0.0, right_moved = 0.0;
  int most_bent_frame = 0;
  for (int frame = 1; frame <= 48; ++frame) {
    INFO("frame " << frame);
    const Mesh m = frame_mesh(frame, rest);
    REQUIRE(m.positions.size() == rest.positions.size());
    const double ratio = volume(m, piece_of, body) / rest_volume;
    smallest = std::min(smallest, ratio);
    largest = std::max(largest, ratio);
    const double bent = head_turn(m);
    if (bent > most_bent) {
      most_bent = bent;
      most_bent_frame = frame;
    }
    widest = std::max(widest, (group_centre(m, "left_flight") - rest_left).norm() / size);
    right_moved = std::max(right_moved, (group_centre(m, "right_flight") - rest_right).norm() / size);
    if (frame == 1) {
      CHECK(ratio == Approx(1.0).epsilon(1e-3));
      CHECK(bent < 0.5);
    }
  }
  // Breathing: +-10% (the neck's bend changes the volume a little too).
  CHECK(largest == Approx(1.1).epsilon(0.01));
  CHECK(smallest == Approx(0.9).epsilon(0.01));
  // The neck: the head turns 90 degrees with the bend's end at its most, on frames 24 and 25, and
  // back at the end.
  CHECK(most_bent == Approx(90.0).margin(3.0));
  CHECK((most_bent_frame == 24 || most_bent_frame == 25));  // the bend peaks half way, frame 24.5
  CHECK(head_turn(frame_mesh(48, rest)) < 10.0);
  // The left wing opens: its flight feathers' tract moves by a large part of the bird's length, and
  // is folded back at the end; the right wing only rides on the breathing body.
  CHECK(widest > 0.2);
  CHECK((group_centre(frame_mesh(48, rest), "left_flight") - rest_left).norm() / size < 0.05);
  CHECK(right_moved < 0.05);
}
