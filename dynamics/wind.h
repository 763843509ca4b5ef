// Wind on guides: a steady air velocity with gusts from seeded 1D value noise that travel with
// the wind, so nearby joints feel the same gust a moment apart.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "groom/dynamics_desc.h"
#include "groom/roots.h"

namespace plume::dynamics {

/// Smooth value noise in [-1, 1]: random values at integer `phase`, hashed from (seed, integer),
/// joined by a smoothstep. Same inputs, same value on any machine.
inline double gust_noise(uint64_t seed, double phase) {
  const double cell = std::floor(phase);
  const double f = phase - cell;
  const int64_t i = int64_t(cell);
  const double a = 2.0 * hash_to_unit(hash_combine(seed, uint64_t(i))) - 1.0;
  const double b = 2.0 * hash_to_unit(hash_combine(seed, uint64_t(i + 1))) - 1.0;
  const double s = f * f * (3.0 - 2.0 * f);
  return a + s * (b - a);
}

/// Air velocity (scene units / s) at `position` and `time` (s):
///   w(t, x) = W (1 + gust * noise(f (t - x.W / |W|^2)))
/// W = settings.wind, f = settings.wind_gust_frequency (Hz). The noise argument is constant on
/// planes moving with the wind, so a gust front crosses the groom at the wind's speed.
inline Eigen::Vector3d wind_velocity(const DynamicsSettings &settings, double time, const Eigen::Vector3d &position) {
  const Eigen::Vector3d wind = settings.wind.cast<double>();
  const double speed2 = wind.squaredNorm();
  if (speed2 == 0.0) return Eigen::Vector3d::Zero();
  if (settings.wind_gust == 0.0f) return wind;
  const double phase = settings.wind_gust_frequency * (time - position.dot(wind) * (1.0 / speed2));
  return wind * (1.0 + settings.wind_gust * gust_noise(settings.seed, phase));
}

/// wind_velocity for many nearby points at one time: the two hashed lattice values of the last
/// noise cell are kept, since the joints of one guide nearly always fall in the same cell or the
/// next one and the hashing is most of the cost. Returns exactly wind_velocity's values.
class WindField {
 public:
  WindField(const DynamicsSettings &settings, double time)
      : wind_(settings.wind.cast<double>()), time_(time), gust_(settings.wind_gust),
        frequency_(settings.wind_gust_frequency), seed_(settings.seed) {
    speed2_ = wind_.squaredNorm();
    inv_speed2_ = 1.0 / speed2_;
  }
  Eigen::Vector3d at(const Eigen::Vector3d &position) {
    if (speed2_ == 0.0) return Eigen::Vector3d::Zero();
    if (gust_ == 0.0f) return wind_;
    // The same arithmetic as wind_velocity and gust_noise, in the same order.
    const double phase = frequency_ * (time_ - position.dot(wind_) * inv_speed2_);
    const double cell = std::floor(phase);
    const double f = phase - cell;
    const int64_t i = int64_t(cell);
    if (i != cell_ || !cached_) {
      a_ = 2.0 * hash_to_unit(hash_combine(seed_, uint64_t(i))) - 1.0;
      b_ = 2.0 * hash_to_unit(hash_combine(seed_, uint64_t(i + 1))) - 1.0;
      cell_ = i;
      cached_ = true;
    }
    const double s = f * f * (3.0 - 2.0 * f);
    return wind_ * (1.0 + gust_ * (a_ + s * (b_ - a_)));
  }

 private:
  Eigen::Vector3d wind_;
  double time_;
  float gust_, frequency_;
  uint64_t seed_;
  double speed2_ = 0.0, inv_speed2_ = 0.0;
  int64_t cell_ = 0;
  bool cached_ = false;
  double a_ = 0.0, b_ = 0.0;
};

}  // namespace plume::dynamics
