// The lane-wise sine and cosine against the C library's, in double precision.
#include <catch2/catch.hpp>

#include <cmath>

#include "skin/lanes.h"

using namespace plume;

TEST_CASE("sin_cos4 matches sine and cosine to 2e-7 over +-1e4 radians, lane by lane", "[interp]") {
  double worst = 0.0;
  int samples = 0;
  for (int i = -200000; i <= 200000; ++i) {
    // Four unrelated angles per call, quadrant boundaries and tiny angles included.
    const skin::Float4 x = {0.05f * float(i), 1.5707963f * float(i % 7), -0.0031f * float(i) + 0.25f, 1e-6f * float(i)};
    skin::Float4 sine, cosine;
    skin::sin_cos4(x, sine, cosine);
    for (int l = 0; l < 4; ++l) {
      worst = std::max(worst, std::abs(double(sine[l]) - std::sin(double(x[l]))));
      worst = std::max(worst, std::abs(double(cosine[l]) - std::cos(double(x[l]))));
      ++samples;
    }
  }
  CHECK(samples == 1600004);
  CHECK(worst < 2e-7);
  // Exact at zero.
  skin::Float4 sine, cosine;
  skin::sin_cos4(skin::Float4{}, sine, cosine);
  CHECK(sine[0] == 0.0f);
  CHECK(cosine[0] == 1.0f);
}

TEST_CASE("log4 matches the logarithm to 1e-7 relative over the normal floats", "[interp]") {
  double worst = 0.0;
  for (int i = 0; i < 400000; ++i) {
    // From 1e-30 to 1e30, and densely around 1 where the result is small.
    const float wide = std::pow(10.0f, -30.0f + 60.0f * float(i) / 400000.0f);
    const skin::Float4 x = {wide, 1.0f + 1e-6f * float(i - 200000), 0.5f + 1e-6f * float(i), 1e-7f + 2.5e-6f * float(i)};
    const skin::Float4 y = skin::log4(x);
    for (int l = 0; l < 4; ++l) {
      const double exact = std::log(double(x[l]));
      worst = std::max(worst, std::abs(double(y[l]) - exact) / std::max(std::abs(exact), 1e-3));
    }
  }
  CHECK(worst < 1e-7);
  CHECK(skin::log4(skin::Float4{} + 1.0f)[0] == 0.0f);
}
