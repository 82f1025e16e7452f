#pragma once

#include <Eigen/Core>

namespace uwscan {

// The symmetric part of a square matrix, (A + A^T) / 2: what a covariance or an information
// matrix is meant to be, once rounding in its products has made it drift from symmetry (an
// eigen-solver for symmetric matrices reads only one triangle, an inverse of a slightly
// asymmetric matrix is asymmetric again).
template <typename Derived>
typename Derived::PlainObject Symmetrized(const Eigen::MatrixBase<Derived>& m) {
  return 0.5 * (m + m.transpose());
}

}  // namespace uwscan
