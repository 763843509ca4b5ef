#include "dynamics/tridiagonal.h"

namespace plume::dynamics {

namespace {
// Thomas algorithm. Elimination of row i-1 from row i:
//   diag'[i] = diag[i] - lower[i] * upper[i-1] / diag'[i-1]
//   rhs'[i]  = rhs[i]  - lower[i] * rhs'[i-1]  / diag'[i-1]
// then back substitution  x[i] = (rhs'[i] - upper[i] x[i+1]) / diag'[i].
// Each row is a step of a serial dependency chain, so its latency is the cost: the reciprocal
// 1 / diag'[i] is taken once (kept in diag) and both passes multiply by it, leaving one division
// per row instead of two.
template <typename Value>
void thomas(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
            std::span<Value> rhs) {
  const size_t n = rhs.size();
  if (n == 0) return;
  for (size_t i = 1; i < n; ++i) {
    const double inverse = 1.0 / diag[i - 1];
    diag[i - 1] = inverse;
    const double factor = lower[i] * inverse;
    diag[i] -= factor * upper[i - 1];
    rhs[i] -= factor * rhs[i - 1];
  }
  diag[n - 1] = 1.0 / diag[n - 1];
  rhs[n - 1] *= diag[n - 1];
  for (size_t i = n - 1; i-- > 0;) rhs[i] = (rhs[i] - upper[i] * rhs[i + 1]) * diag[i];
}
}  // namespace

void solve_tridiagonal(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
                       std::span<double> rhs) {
  thomas(lower, diag, upper, rhs);
}

void solve_tridiagonal(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
                       std::span<Eigen::Vector3d> rhs) {
  thomas(lower, diag, upper, rhs);
}

}  // namespace plume::dynamics
