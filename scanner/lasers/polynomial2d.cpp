#include "scanner/lasers/polynomial2d.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

// The monomials of u in the class's term order, written into `row` (TermCount(degree) long).
template <typename Row>
void Monomials(const Eigen::Vector2d& u, int degree, Row&& row) {
  std::array<double, Polynomial2d::kMaxDegree + 1> pu{}, pv{};
  pu[0] = pv[0] = 1.0;
  for (int k = 1; k <= degree; ++k) {
    pu[k] = pu[k - 1] * u.x();
    pv[k] = pv[k - 1] * u.y();
  }
  int term = 0;
  for (int k = 0; k <= degree; ++k) {
    for (int j = 0; j <= k; ++j) row[term++] = pu[k - j] * pv[j];
  }
}

}  // namespace

Polynomial2d::Polynomial2d() : coefficients_(Eigen::VectorXd::Zero(1)) {}

Polynomial2d::Polynomial2d(int degree, const Eigen::Vector2d& center, const Eigen::Vector2d& scale,
                           const Eigen::VectorXd& coefficients)
    : degree_(degree), center_(center), scale_(scale), coefficients_(coefficients) {
  if (degree < 0 || degree > kMaxDegree) {
    throw Error("polynomial: degree must be in [0, " + std::to_string(kMaxDegree) + "], got " +
                std::to_string(degree));
  }
  if (!center.allFinite()) throw Error("polynomial: center must be finite");
  if (!(scale.allFinite() && scale.minCoeff() > 0.0)) {
    throw Error("polynomial: scale must be positive and finite on both axes");
  }
  if (coefficients.size() != TermCount(degree)) {
    throw Error("polynomial: degree " + std::to_string(degree) + " needs " +
                std::to_string(TermCount(degree)) + " coefficients, got " +
                std::to_string(coefficients.size()));
  }
  if (!coefficients.allFinite()) throw Error("polynomial: coefficients must be finite");
}

Polynomial2d Polynomial2d::Fit(std::span<const Eigen::Vector2d> x, std::span<const double> y,
                               int degree) {
  if (degree < 0 || degree > kMaxDegree) {
    throw Error("polynomial fit: degree must be in [0, " + std::to_string(kMaxDegree) + "], got " +
                std::to_string(degree));
  }
  if (x.size() != y.size()) {
    throw Error("polynomial fit: " + std::to_string(x.size()) + " inputs but " +
                std::to_string(y.size()) + " values");
  }
  const int terms = TermCount(degree);
  const Eigen::Index n = static_cast<Eigen::Index>(x.size());
  if (n < terms) {
    throw Error("polynomial fit: degree " + std::to_string(degree) + " needs at least " +
                std::to_string(terms) + " points, got " + std::to_string(n));
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!x[i].allFinite() || !std::isfinite(y[i])) {
      throw Error("polynomial fit: point " + std::to_string(i) + " is not finite");
    }
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
  }
  const Eigen::Vector2d center = 0.5 * (lo + hi);
  Eigen::Vector2d scale = 0.5 * (hi - lo);
  for (int axis = 0; axis < 2; ++axis) {
    // Half-range relative to the magnitude: inputs equal to rounding carry no information.
    const double magnitude = std::max(std::abs(lo[axis]), std::abs(hi[axis]));
    if (!(scale[axis] > 64.0 * std::numeric_limits<double>::epsilon() * magnitude)) {
      if (degree >= 1) {
        throw Error("polynomial fit: the inputs do not vary along axis " + std::to_string(axis) +
                    ", so no polynomial of degree " + std::to_string(degree) + " is determined");
      }
      scale[axis] = 1.0;  // a constant needs no spread
    }
  }

  Eigen::MatrixXd vandermonde(n, terms);
  Eigen::VectorXd values(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    Monomials((x[i] - center).cwiseQuotient(scale), degree, vandermonde.row(i));
    values[i] = y[i];
  }
  // The SVD both solves and reports the conditioning, so clustered data fail with a number
  // instead of returning coefficients dominated by rounding.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(vandermonde,
                                              Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  const double condition = sigma[0] / sigma[terms - 1];
  if (!(condition <= kMaxCondition)) {
    std::ostringstream message;
    message << "polynomial fit: the " << n << " inputs cannot support degree " << degree
            << " (condition number " << condition << " > " << kMaxCondition
            << "); they are clustered or lie on a curve of low degree: spread them over the "
               "domain or lower the degree";
    throw Error(message.str());
  }
  return Polynomial2d(degree, center, scale, svd.solve(values));
}

double Polynomial2d::Evaluate(const Eigen::Vector2d& x) const {
  std::array<double, TermCount(kMaxDegree)> row{};
  Monomials(Normalise(x), degree_, row);
  double sum = 0.0;
  for (int i = 0; i < coefficients_.size(); ++i) sum += coefficients_[i] * row[i];
  return sum;
}

}  // namespace uwscan::scanner
