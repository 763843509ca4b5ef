#include "dynamics/tridiagonal.h"

#include <cmath>

namespace plume::dynamics {

namespace {
// Thomas algorithm. Elimination of row i-1 from row i:
//   diag'[i] = diag[i] - lower[i] * upper[i-1] / diag'[i-1]
//   rhs'[i]  = rhs[i]  - lower[i] * rhs'[i-1]  / diag'[i-1]
// then back substitution  x[i] = (rhs'[i] - upper[i] x[i+1]) / diag'[i].
// Each row is a step of a serial dependency chain, so its latency is the cost. The pivot
// recurrence as written puts a division on that chain; it is taken off through the scaled
// leading minors q_i = prod_{k <= i} diag'[k] / diag[k] (q_{-1} = q_0 = 1), for which it reads
//   q_i = q_{i-1} - c_i q_{i-2},   c_i = lower[i] upper[i-1] / (diag[i] diag[i-1]),
// one multiply-add per row; the reciprocals 1 / diag'[i] = q_{i-1} / (diag[i] q_i) and the c_i are
// independent divisions that overlap. Both passes then multiply by the reciprocals.
template <typename Value>
void thomas(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
            std::span<Value> rhs) {
  const size_t n = rhs.size();
  if (n == 0) return;
  // The minors shrink (or grow) geometrically with the row count: rescaled by a power of two
  // (exact, their ratios unchanged) before they could leave the double range.
  constexpr double kSmall = 0x1p-500, kLarge = 0x1p500;
  double q_prev = 1.0, q = 1.0, diag_prev = diag[0];
  diag[0] = 1.0 / diag[0];
  for (size_t i = 1; i < n; ++i) {
    const double d = diag[i];
    const double next = q - lower[i] * upper[i - 1] / (d * diag_prev) * q_prev;
    q_prev = q;
    q = next;
    diag[i] = q_prev / (d * q);
    diag_prev = d;
    const double magnitude = std::abs(q);
    if (magnitude < kSmall) {
      q *= kLarge;
      q_prev *= kLarge;
    } else if (magnitude > kLarge) {
      q *= kSmall;
      q_prev *= kSmall;
    }
  }
  for (size_t i = 1; i < n; ++i) rhs[i] -= (lower[i] * diag[i - 1]) * rhs[i - 1];
  rhs[n - 1] *= diag[n - 1];
  // x[i] = rhs'[i] / diag'[i] - (upper[i] / diag'[i]) x[i+1]: one multiply-add on the chain.
  for (size_t i = n - 1; i-- > 0;) rhs[i] = rhs[i] * diag[i] - (upper[i] * diag[i]) * rhs[i + 1];
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
