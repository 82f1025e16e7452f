#pragma once

#include <Eigen/Core>
#include <span>

namespace uwscan::scanner {

// A bivariate polynomial of total degree d in inputs normalised per axis,
//   u = (x - center) / scale   (component-wise),
//   f(x) = sum over k = 0..d, j = 0..k of c[k(k+1)/2 + j] * u0^(k-j) * u1^j,
// i.e. terms in order 1, u0, u1, u0^2, u0 u1, u1^2, u0^3, ... ((d+1)(d+2)/2 of them; 21 for
// the seed's fifth-order projection functions).
//
// Why normalised: the fit is posed on inputs in [-1, 1], where the monomials up to degree 5
// have comparable magnitudes, so the least-squares matrix is well conditioned whatever the
// units (volts, millivolts, metres) and wherever the data sit; raw inputs of 100 V would put
// 1e10 between the columns of degree 0 and 5.
class Polynomial2d {
 public:
  static constexpr int kMaxDegree = 10;
  static constexpr int TermCount(int degree) { return (degree + 1) * (degree + 2) / 2; }

  // The zero polynomial of degree 0 on the unit square.
  Polynomial2d();
  // Throws uwscan::Error when degree is outside [0, kMaxDegree], a scale component is not
  // positive and finite, or the coefficient count is not TermCount(degree).
  Polynomial2d(int degree, const Eigen::Vector2d& center, const Eigen::Vector2d& scale,
               const Eigen::VectorXd& coefficients);

  // Linear least squares on the normalised Vandermonde matrix, solved by SVD (never the normal
  // equations, which would square its condition number). center/scale are the midpoint and
  // half-range of the inputs per axis. Throws uwscan::Error when
  //  - x and y differ in size, or hold fewer than TermCount(degree) points;
  //  - an input is not finite;
  //  - the inputs do not vary along an axis (degree >= 1), or are so clustered (on a line, in
  //    a few tight clumps) that they cannot support the degree: the matrix's condition number
  //    exceeds kMaxCondition. The message gives the condition number.
  static Polynomial2d Fit(std::span<const Eigen::Vector2d> x, std::span<const double> y,
                          int degree);
  // Condition number (largest / smallest singular value) beyond which Fit refuses: 1e8 leaves
  // the coefficients 8 of double's 16 digits, well above any calibration's data noise, while
  // data spread over the domain give about 50 for degree 5 (grids of 6x6 to 41x41: 45-75).
  static constexpr double kMaxCondition = 1e8;

  double Evaluate(const Eigen::Vector2d& x) const;
  double operator()(const Eigen::Vector2d& x) const { return Evaluate(x); }

  int degree() const { return degree_; }
  const Eigen::Vector2d& center() const { return center_; }
  const Eigen::Vector2d& scale() const { return scale_; }
  const Eigen::VectorXd& coefficients() const { return coefficients_; }
  Eigen::Vector2d Normalise(const Eigen::Vector2d& x) const {
    return (x - center_).cwiseQuotient(scale_);
  }

 private:
  int degree_ = 0;
  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d scale_ = Eigen::Vector2d::Ones();
  Eigen::VectorXd coefficients_;
};

}  // namespace uwscan::scanner
