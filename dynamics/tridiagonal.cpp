#include "dynamics/tridiagonal.h"

namespace plume::dynamics {

namespace {
// Thomas algorithm. Elimination of row i-1 from row i:
//   diag'[i] = diag[i] - lower[i] * upper[i-1] / diag'[i-1]
//   rhs'[i]  = rhs[i]  - lower[i] * rhs'[i-1]  / diag'[i-1]
// then back substitution  x[i] = (rhs'[i] - upper[i] x[i+1]) / diag'[i].
template <typename Value>
void thomas(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
            std::span<Value> rhs) {
  const size_t n = rhs.size();
  if (n == 0) return;
  for (size_t i = 1; i < n; ++i) {
    const double factor = lower[i] / diag[i - 1];
    diag[i] -= factor * upper[i - 1];
    rhs[i] -= factor * rhs[i - 1];
  }
  rhs[n - 1] /= diag[n - 1];
  for (size_t i = n - 1; i-- > 0;) rhs[i] = (rhs[i] - upper[i] * rhs[i + 1]) / diag[i];
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
