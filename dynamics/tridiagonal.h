// Direct solve of tridiagonal systems (Thomas algorithm): the linear-time kernel of the guide
// solver, used for the implicit forces (three right-hand sides) and the segment tensions (one).
#pragma once

#include <Eigen/Core>
#include <span>

namespace plume::dynamics {

/// Solves  lower[i] x[i-1] + diag[i] x[i] + upper[i] x[i+1] = rhs[i]  for i in [0, n), in place:
/// on return `rhs` holds x. lower[0] and upper[n-1] are ignored. `diag` is overwritten (scratch).
/// All spans have n entries. Forward elimination then back substitution (the pivots through the
/// scaled leading minors, so that no division sits on the serial chain), no pivoting: the matrix must be diagonally dominant or symmetric positive definite, which
/// both of the solver's systems are (see docs/dynamics.md).
void solve_tridiagonal(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
                       std::span<double> rhs);
/// The same with a 3-vector right-hand side per row (three systems sharing one matrix).
void solve_tridiagonal(std::span<const double> lower, std::span<double> diag, std::span<const double> upper,
                       std::span<Eigen::Vector3d> rhs);

}  // namespace plume::dynamics
