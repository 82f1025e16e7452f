#pragma once

#include <Eigen/Core>

namespace uwscan {

// The symmetric part of a square matrix, (A + A^T) / 2: what a covariance or an information
// matrix is meant to be, once rounding in its products has made it drift from symmetry (an
// eigen-solver for symmetric matrices reads only one triangle, an inverse of a slightly
// asymmetric matrix is asymmetric again). The result is a new matrix, so `A = Symmetrized(A)` is
// exactly symmetric; written in place, `A = 0.5 * (A + A.transpose())` is not: Eigen assigns it
// element by element without a temporary, and reads entries it has already overwritten.
template <typename Derived>
typename Derived::PlainObject Symmetrized(const Eigen::MatrixBase<Derived>& m) {
  return 0.5 * (m + m.transpose());
}

}  // namespace uwscan
