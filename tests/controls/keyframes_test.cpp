// Keyed amounts: held outside the keys, exact at the keys, linear or smooth (monotone, C1) between.
#include <catch2/catch.hpp>

#include <cmath>

#include "controls/keyframes.h"
#include "controls_fixtures.h"
#include "groom/roots.h"

using namespace plume;
using plume::test::keys;

TEST_CASE("keyed values hold before the first key and after the last, and pass through every key", "[controls]") {
  for (const KeyInterpolation interpolation : {KeyInterpolation::linear, KeyInterpolation::smooth}) {
    const Keyed<float> k = keys({{1, 0.2f}, {5, 1.0f}, {12, -0.5f}, {13, -0.5f}, {20, 0.75f}}, interpolation);
    CHECK(controls::value_at(k, -100.0) == 0.2f);
    CHECK(controls::value_at(k, 1.0) == 0.2f);
    CHECK(controls::value_at(k, 20.0) == 0.75f);
    CHECK(controls::value_at(k, 1e6) == 0.75f);
    for (size_t i = 0; i < k.frames.size(); ++i)
      CHECK(controls::value_at(k, k.frames[i]) == Approx(k.values[i]).margin(1e-6));
  }
  const Keyed<float> one = Keyed<float>::constant(0.3f);
  CHECK(controls::value_at(one, -5.0) == 0.3f);
  CHECK(controls::value_at(one, 5.0) == 0.3f);
}

TEST_CASE("linear keys are straight lines between keys, and keys of 0 give exactly 0", "[controls]") {
  const Keyed<float> k = keys({{0, 0.0f}, {10, 1.0f}});
  for (int f = 0; f <= 10; ++f) CHECK(controls::value_at(k, f) == Approx(0.1 * f).margin(1e-6));
  const Keyed<float> zero = keys({{1, 0.0f}, {7, 0.0f}, {9, 0.0f}}, KeyInterpolation::smooth);
  for (double f = -2.0; f < 12.0; f += 0.25) CHECK(controls::value_at(zero, f) == 0.0f);
}

TEST_CASE(
    "smooth keys never leave the values of the two keys around them, are monotone on monotone keys, and have no "
    "kink at a key",
    "[controls]") {
  for (uint64_t seed = 0; seed < 200; ++seed) {
    Keyed<float> k;
    k.interpolation = KeyInterpolation::smooth;
    double frame = 0.0;
    const bool monotone = seed % 2 == 0;
    float value = 0.0f;
    const int n = 2 + int(hash_to_unit(hash64(seed)) * 6.0f);
    for (int i = 0; i < n; ++i) {
      frame += 0.5 + 10.0 * hash_to_unit(hash_combine(seed, uint64_t(2 * i)));
      const float step = hash_to_unit(hash_combine(seed, uint64_t(2 * i + 1)));
      value = monotone ? value + step : 2.0f * step - 1.0f;
      k.frames.push_back(frame);
      k.values.push_back(value);
    }
    for (size_t i = 0; i + 1 < k.frames.size(); ++i) {
      const float lo = std::min(k.values[i], k.values[i + 1]), hi = std::max(k.values[i], k.values[i + 1]);
      float previous = k.values[i];
      for (int s = 1; s <= 50; ++s) {
        const double f = k.frames[i] + (k.frames[i + 1] - k.frames[i]) * s / 50.0;
        const float v = controls::value_at(k, f);
        CHECK(v >= lo - 1e-6f);
        CHECK(v <= hi + 1e-6f);
        if (monotone) CHECK(v >= previous - 1e-6f);
        previous = v;
      }
    }
    // C1: the slopes just before and just after each inner key agree.
    for (size_t i = 1; i + 1 < k.frames.size(); ++i) {
      const double h = 1e-3, f = k.frames[i];
      const double left = (controls::value_at(k, f) - controls::value_at(k, f - h)) / h;
      const double right = (controls::value_at(k, f + h) - controls::value_at(k, f)) / h;
      CHECK(left == Approx(right).margin(0.02 + 0.02 * std::abs(left)));
    }
  }
}

TEST_CASE("keyed vectors are keyed component by component", "[controls]") {
  Keyed<Eigen::Vector3f> k;
  k.frames = {1, 11};
  k.values = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, -2, 4)};
  const Eigen::Vector3f mid = controls::value_at(k, 6.0);
  CHECK(mid.x() == Approx(0.5));
  CHECK(mid.y() == Approx(-1.0));
  CHECK(mid.z() == Approx(2.0));
  CHECK(controls::value_at(k, 0.0) == Eigen::Vector3f::Zero());
}
