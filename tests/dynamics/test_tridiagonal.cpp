#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "dynamics/tridiagonal.h"
#include "groom/roots.h"

using plume::dynamics::solve_tridiagonal;

namespace {

// Residual max_i |lower x[i-1] + diag x[i] + upper x[i+1] - rhs[i]| / max |rhs|.
double relative_residual(const std::vector<double> &lower, const std::vector<double> &diag,
                         const std::vector<double> &upper, const std::vector<double> &x, const std::vector<double> &rhs) {
  const size_t n = x.size();
  double worst = 0.0, scale = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double row = diag[i] * x[i];
    if (i > 0) row += lower[i] * x[i - 1];
    if (i + 1 < n) row += upper[i] * x[i + 1];
    worst = std::max(worst, std::abs(row - rhs[i]));
    scale = std::max(scale, std::abs(rhs[i]));
  }
  return worst / scale;
}

}  // namespace

TEST_CASE("tridiagonal solve: random diagonally dominant systems", "[dynamics]") {
  for (size_t n : {1, 2, 3, 25, 200}) {
    std::vector<double> lower(n), diag(n), upper(n), rhs(n);
    for (size_t i = 0; i < n; ++i) {
      lower[i] = plume::hash_to_unit(plume::hash_combine(1, i)) - 0.5;
      upper[i] = plume::hash_to_unit(plume::hash_combine(2, i)) - 0.5;
      diag[i] = 1.0 + plume::hash_to_unit(plume::hash_combine(3, i));
      rhs[i] = plume::hash_to_unit(plume::hash_combine(4, i)) - 0.5;
    }
    std::vector<double> x = rhs, scratch = diag;
    solve_tridiagonal(lower, scratch, upper, x);
    CHECK(relative_residual(lower, diag, upper, x, rhs) < 1e-13);
  }
}

TEST_CASE("tridiagonal solve: long chains whose leading minors leave the double range", "[dynamics]") {
  // The constraint matrix of a straight chain of equal masses, scaled: pivots (i + 1) / i, so the
  // scaled minors fall like 2^-i (and the minors themselves like scale^i), far outside the double
  // range after a few thousand rows. The solution of A x = A x_true must come back.
  for (double scale : {1e-30, 1.0, 1e30}) {
    const size_t n = 4000;
    std::vector<double> lower(n, -scale), diag(n, 2.0 * scale), upper(n, -scale), x_true(n), rhs(n);
    for (size_t i = 0; i < n; ++i) x_true[i] = std::sin(0.01 * double(i)) + 0.5;
    for (size_t i = 0; i < n; ++i)
      rhs[i] = diag[i] * x_true[i] + (i > 0 ? lower[i] * x_true[i - 1] : 0.0) + (i + 1 < n ? upper[i] * x_true[i + 1] : 0.0);
    std::vector<double> x = rhs, scratch = diag;
    solve_tridiagonal(lower, scratch, upper, x);
    double error = 0.0;
    for (size_t i = 0; i < n; ++i) error = std::max(error, std::abs(x[i] - x_true[i]));
    CHECK(std::isfinite(error));
    CHECK(error < 1e-6);
    // Three right-hand sides at once give the values of three scalar solves (to rounding: the
    // compiler may contract the two paths into multiply-adds differently).
    std::vector<Eigen::Vector3d> x3(n);
    for (size_t i = 0; i < n; ++i) x3[i] = Eigen::Vector3d(rhs[i], -rhs[i], 2.0 * rhs[i]);
    scratch = diag;
    solve_tridiagonal(lower, scratch, upper, x3);
    double difference = 0.0;
    for (size_t i = 0; i < n; ++i) difference = std::max(difference, (x3[i] - Eigen::Vector3d(x[i], -x[i], 2.0 * x[i])).norm());
    CHECK(difference < 1e-12);
  }
}
