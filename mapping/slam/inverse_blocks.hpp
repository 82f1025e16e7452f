#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <optional>
#include <vector>

// Selected blocks of the inverse of a sparse information matrix: the marginal covariances of a
// pose graph without forming the whole inverse.
namespace uwscan::mapping {

// Rows and columns [start, start + size) of a matrix.
struct IndexRange {
  int start = 0;
  int size = 0;
};

// The diagonal blocks of information^-1 for the given ranges, in their order.
//
// The information (symmetric, both triangles or the lower one stored) is factored as
// P H P^T = L D L^T (sparse LDL^T, AMD ordering), and only the entries of the inverse on L's
// pattern are computed, from the last column to the first (Takahashi's recursion:
// Z = D^-1 L^-1 + (I - L^T) Z). Each requested block lies on that pattern because its entries
// are made structural before the factorisation. Everything is scalar sparse arithmetic in a
// fixed order, so the bits do not depend on threads or on where memory was allocated.
//
// std::nullopt when the matrix is not positive definite or a pivot falls below
// min_pivot_ratio times its row's diagonal (a direction nothing constrains, to rounding).
// Throws uwscan::Error for a block outside the matrix.
std::optional<std::vector<Eigen::MatrixXd>> InverseBlocks(Eigen::SparseMatrix<double> information,
                                                          const std::vector<IndexRange>& blocks,
                                                          double min_pivot_ratio = 1e-12);

}  // namespace uwscan::mapping
