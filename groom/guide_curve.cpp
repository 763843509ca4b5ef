#include "groom/guide_curve.h"

#include <Eigen/Geometry>

#include "groom/mesh_query.h"

namespace plume {

void guide_curve(std::span<const Eigen::Vector3f> given, float tiny, std::vector<CurvePiece> &r_pieces) {
  r_pieces.clear();
  std::vector<Eigen::Vector3f> points;
  points.reserve(given.size());
  for (const Eigen::Vector3f &p : given)
    if (points.empty() || (p - points.back()).norm() > tiny) points.push_back(p);
  const size_t count = points.size();
  if (count < 2) return;  // a guide of no length shows no direction
  std::vector<Eigen::Vector3f> chords(count - 1), tangents(count);
  for (size_t j = 0; j + 1 < count; ++j) chords[j] = (points[j + 1] - points[j]).normalized();
  for (size_t j = 1; j + 1 < count; ++j) {
    const Eigen::Vector3f sum = chords[j - 1] + chords[j];
    tangents[j] = sum.norm() > 1e-6f ? Eigen::Vector3f(sum.normalized()) : chords[j];
  }
  auto mirror = [](const Eigen::Vector3f &inner, const Eigen::Vector3f &chord) {
    const Eigen::Vector3f m = 2.0f * chord.dot(inner) * chord - inner;
    return m.norm() > 1e-6f ? Eigen::Vector3f(m.normalized()) : chord;
  };
  tangents[0] = count > 2 ? mirror(tangents[1], chords[0]) : chords[0];
  tangents[count - 1] = count > 2 ? mirror(tangents[count - 2], chords[count - 2]) : chords[0];
  r_pieces.reserve(count - 1);
  for (size_t j = 0; j + 1 < count; ++j) {
    const Eigen::Vector3f &p0 = points[j], &p1 = points[j + 1];
    const float length = (p1 - p0).norm();
    const Eigen::Vector3f m0 = length * tangents[j], m1 = length * tangents[j + 1];
    r_pieces.push_back({p0, m0, 3.0f * (p1 - p0) - 2.0f * m0 - m1, 2.0f * (p0 - p1) + m0 + m1, p1});
  }
}

double curve_length(std::span<const CurvePiece> pieces) {
  // Gauss-Legendre nodes and weights on [-1, 1], positive half.
  static constexpr double node[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                     0.9602898564975363};
  static constexpr double weight[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                       0.1012285362903763};
  double total = 0.0;
  for (const CurvePiece &piece : pieces)
    for (int i = 0; i < 4; ++i)
      for (const double sign : {-1.0, 1.0})
        total += 0.5 * weight[i] * double(piece.derivative(float(0.5 + 0.5 * sign * node[i])).norm());
  return total;
}

std::vector<Eigen::Vector3f> sample_curve(std::span<const CurvePiece> pieces, int per_piece) {
  std::vector<Eigen::Vector3f> points;
  if (pieces.empty()) return points;
  points.reserve(pieces.size() * size_t(per_piece) + 1);
  for (const CurvePiece &piece : pieces)
    for (int i = 0; i < per_piece; ++i) points.push_back(piece.at(float(i) / float(per_piece)));
  points.push_back(pieces.back().end);
  return points;
}

bool guide_runs_low(std::span<const Eigen::Vector3f> samples, const MeshQuery &query, float band,
                    std::vector<float> *r_distances) {
  if (r_distances) r_distances->clear();
  bool risen = false;
  for (size_t j = 0; j < samples.size(); ++j) {
    const float distance = query.signed_distance(samples[j]);
    if (r_distances) r_distances->push_back(distance);
    if (j > 0 && (distance < 0.0f || (risen && distance < band))) return true;
    risen = risen || distance >= band;
  }
  return false;
}

}  // namespace plume
