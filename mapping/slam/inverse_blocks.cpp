#include "mapping/slam/inverse_blocks.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// The strictly lower factor L in compressed columns, rows ascending within each column, and
// the inverse Z on the same pattern (plus its diagonal).
struct SelectedInverse {
  std::vector<int> column_start;  // n + 1
  std::vector<int> rows;
  std::vector<double> l;
  std::vector<double> z;
  Eigen::VectorXd z_diagonal;

  // Z(i, k) for i, k on the pattern (Z is symmetric: stored in the column of the smaller index).
  double At(int i, int k) const {
    if (i == k) return z_diagonal[i];
    if (i < k) std::swap(i, k);
    const auto begin = rows.begin() + column_start[static_cast<size_t>(k)];
    const auto end = rows.begin() + column_start[static_cast<size_t>(k) + 1];
    const auto it = std::lower_bound(begin, end, i);
    // Every entry read lies on the pattern (a column's rows are a clique of the factor's graph;
    // the blocks were made structural): a miss is a broken invariant, never wrong numbers.
    if (it == end || *it != i)
      throw std::logic_error("InverseBlocks: an entry off the factor's pattern");
    return z[static_cast<size_t>(it - rows.begin())];
  }
};

SelectedInverse CopyFactor(const Eigen::SparseMatrix<double>& L) {
  SelectedInverse s;
  const int n = static_cast<int>(L.cols());
  s.column_start.assign(static_cast<size_t>(n) + 1, 0);
  std::vector<std::pair<int, double>> column;
  for (int j = 0; j < n; ++j) {
    column.clear();
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, j); it; ++it) {
      if (it.row() > j) column.emplace_back(static_cast<int>(it.row()), it.value());
    }
    std::sort(column.begin(), column.end());
    for (const auto& [row, value] : column) {
      s.rows.push_back(row);
      s.l.push_back(value);
    }
    s.column_start[static_cast<size_t>(j) + 1] = static_cast<int>(s.rows.size());
  }
  s.z.assign(s.rows.size(), 0.0);
  s.z_diagonal = Eigen::VectorXd::Zero(n);
  return s;
}

// Z(i, j) = delta_ij / d_j - sum_{k > j, L(k, j) != 0} Z(i, k) L(k, j), for i >= j on the pattern.
// The rows of column j form a clique of the factor's graph, so every Z(i, k) it reads lies on
// the pattern, in a column already done.
//
// For column j with rows r_0 < ... < r_{c-1}, each sum over q takes its terms Z(r_p, r_q) L(r_q, j)
// in the order of q, as written above (so the bits are those of the formula summed term by term).
// The terms are found by reading the columns r_0, r_1, ... once each, not by searching: column
// r_q holds Z(r_p, r_q) for the rows r_p > r_q, which is the term q of sum p and, Z being
// symmetric, the term p of sum q. Sum p thus receives its terms q < p from the columns before
// its own, then its diagonal term, then its terms q > p from its own column, in order.
void FillInverseOnPattern(SelectedInverse& s, const Eigen::VectorXd& d) {
  const int n = static_cast<int>(d.size());
  std::vector<double> sums;
  std::vector<int> position(static_cast<size_t>(n), -1);  // a row's place in column j, or -1
  for (int j = n - 1; j >= 0; --j) {
    const int begin = s.column_start[static_cast<size_t>(j)];
    const int end = s.column_start[static_cast<size_t>(j) + 1];
    const int c = end - begin;
    if (c == 0) {
      s.z_diagonal[j] = 1.0 / d[j];
      continue;
    }
    const auto row = [&](int p) { return s.rows[static_cast<size_t>(begin + p)]; };
    const auto l = [&](int p) { return s.l[static_cast<size_t>(begin + p)]; };
    const int last_row = row(c - 1);
    for (int p = 0; p < c; ++p) position[static_cast<size_t>(row(p))] = p;
    sums.assign(static_cast<size_t>(c), 0.0);
    for (int q = 0; q < c; ++q) {
      const int k = row(q);
      double own = sums[static_cast<size_t>(q)] + s.z_diagonal[k] * l(q);  // sum q, in a register
      int found = 0;
      for (int e = s.column_start[static_cast<size_t>(k)];
           e < s.column_start[static_cast<size_t>(k) + 1]; ++e) {
        const int i = s.rows[static_cast<size_t>(e)];
        if (i > last_row) break;
        const int p = position[static_cast<size_t>(i)];
        if (p < 0) continue;
        ++found;
        const double z = s.z[static_cast<size_t>(e)];
        sums[static_cast<size_t>(p)] += z * l(q);
        own += z * l(p);
      }
      sums[static_cast<size_t>(q)] = own;
      // Every entry needed lies on the pattern: a miss is a broken invariant, never wrong
      // numbers.
      if (found != c - 1 - q)
        throw std::logic_error("InverseBlocks: an entry off the factor's pattern");
    }
    for (int p = 0; p < c; ++p) {
      position[static_cast<size_t>(row(p))] = -1;
      s.z[static_cast<size_t>(begin + p)] = -sums[static_cast<size_t>(p)];
    }
    double sum = 0.0;
    for (int p = begin; p < end; ++p)
      sum += s.z[static_cast<size_t>(p)] * s.l[static_cast<size_t>(p)];
    s.z_diagonal[j] = 1.0 / d[j] - sum;
  }
}

}  // namespace

std::optional<std::vector<Eigen::MatrixXd>> InverseBlocks(Eigen::SparseMatrix<double> information,
                                                          const std::vector<IndexRange>& blocks,
                                                          double min_pivot_ratio) {
  const int n = static_cast<int>(information.rows());
  if (information.cols() != n) throw Error("InverseBlocks: the information must be square");
  std::vector<Eigen::Triplet<double>> structural;
  for (const IndexRange& b : blocks) {
    if (b.start < 0 || b.size < 1 || b.start > n || b.size > n - b.start) {
      throw Error("InverseBlocks: block [" + std::to_string(b.start) + ", +" +
                  std::to_string(b.size) + ") outside a " + std::to_string(n) + "-row matrix");
    }
    for (int a = b.start; a < b.start + b.size; ++a) {
      for (int c = b.start; c < b.start + b.size; ++c) structural.emplace_back(a, c, 0.0);
    }
  }
  Eigen::SparseMatrix<double> zeros(n, n);
  zeros.setFromTriplets(structural.begin(), structural.end());
  information += zeros;  // explicit zeros stay stored: the blocks' entries are on L's pattern

  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(
      information);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXd d = ldlt.vectorD();
  // P H P^T = L D L^T with (P x)[perm[a]] = x[a]: H^-1(a, c) = Z(perm[a], perm[c]).
  const auto& perm = ldlt.permutationP().indices();
  if (perm.size() != n) throw std::logic_error("InverseBlocks: the ordering gave no permutation");
  // Each pivot is what is left of its row's diagonal once the rows before it are eliminated:
  // a vanishing fraction means the row is (numerically) a combination of them. Relative to its
  // own diagonal, the test does not depend on the units of the row (radians, metres).
  for (int a = 0; a < n; ++a) {
    const double diagonal = information.coeff(a, a);
    if (!(diagonal > 0.0) || !(d[perm[a]] > min_pivot_ratio * diagonal)) return std::nullopt;
  }

  SelectedInverse inverse = CopyFactor(ldlt.matrixL().nestedExpression());
  FillInverseOnPattern(inverse, d);

  std::vector<Eigen::MatrixXd> out;
  out.reserve(blocks.size());
  for (const IndexRange& b : blocks) {
    Eigen::MatrixXd block(b.size, b.size);
    for (int a = 0; a < b.size; ++a) {
      for (int c = 0; c < b.size; ++c)
        block(a, c) = inverse.At(perm[b.start + a], perm[b.start + c]);
    }
    out.push_back(std::move(block));
  }
  return out;
}

}  // namespace uwscan::mapping
