#include "scanner/common/symmetrized.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

namespace uwscan {
namespace {

// Assigned to the matrix it reads, the symmetric part is exactly symmetric, and the same bits as
// into a new matrix. (Written in place as 0.5 * (A + A^T), Eigen overwrote the lower triangle
// before reading it for the upper one: SLAM's figures moved by 1e-10 when that was fixed.)
TEST(Symmetrized, InPlaceIsExactlySymmetricAndEqualsTheCopy) {
  Eigen::Matrix<double, 6, 6> a;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) a(r, c) = 1.0 / (1.0 + r + 2.7 * c) + 0.1 * r * r - 0.3 * c;
  }
  const Eigen::Matrix<double, 6, 6> copy = Symmetrized(a);
  a = Symmetrized(a);
  EXPECT_TRUE(a == a.transpose());
  EXPECT_TRUE(a == copy);
}

}  // namespace
}  // namespace uwscan
