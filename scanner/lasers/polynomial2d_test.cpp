#include "scanner/lasers/polynomial2d.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

// A known degree-5 polynomial in raw inputs (volts): every term of degree <= 5 present, with
// mixed signs and sizes, so that no term can be dropped or mis-ordered unnoticed.
double Known(const Eigen::Vector2d& v) {
  const double x = v.x(), y = v.y();
  return 0.3 - 1.7 * x + 0.9 * y + 0.05 * x * x - 0.11 * x * y + 0.07 * y * y + 0.013 * x * x * x -
         0.002 * x * x * y + 0.004 * x * y * y - 0.009 * y * y * y + 3e-4 * std::pow(x, 4) -
         2e-4 * x * x * x * y + 1e-4 * x * x * y * y - 4e-4 * x * y * y * y +
         2e-4 * std::pow(y, 4) + 2e-5 * std::pow(x, 5) - 1e-5 * std::pow(x, 4) * y +
         3e-5 * std::pow(x, 3) * y * y - 2e-5 * x * x * std::pow(y, 3) + 1e-5 * x * std::pow(y, 4) -
         3e-5 * std::pow(y, 5);
}

std::vector<Eigen::Vector2d> Grid(int n, double lo, double hi) {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      points.emplace_back(lo + (hi - lo) * i / (n - 1), lo + (hi - lo) * j / (n - 1));
    }
  }
  return points;
}

std::vector<double> Values(const std::vector<Eigen::Vector2d>& x, double input_scale = 1.0) {
  std::vector<double> y;
  for (const Eigen::Vector2d& p : x) y.push_back(Known(p / input_scale));
  return y;
}

std::string FitError(std::span<const Eigen::Vector2d> x, std::span<const double> y, int degree) {
  try {
    Polynomial2d::Fit(x, y, degree);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "fitted without error";
  return "";
}

TEST(Polynomial2d, RecoversAKnownDegree5PolynomialExactly) {
  const std::vector<Eigen::Vector2d> x = Grid(11, -10.0, 10.0);
  const Polynomial2d f = Polynomial2d::Fit(x, Values(x), 5);
  EXPECT_EQ(f.degree(), 5);
  EXPECT_EQ(f.coefficients().size(), 21);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> volts(-10.0, 10.0);
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d v{volts(rng), volts(rng)};
    worst = std::max(worst, std::abs(f(v) - Known(v)));
  }
  // Values reach ~40 here; exact recovery up to rounding.
  EXPECT_LT(worst, 1e-12);
}

TEST(Polynomial2d, TermOrderIsDocumented) {
  // c = 1 for u0^2 only (index 3), on the unit square: f = u0^2.
  Eigen::VectorXd c = Eigen::VectorXd::Zero(6);
  c[3] = 1.0;
  const Polynomial2d square(2, Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones(), c);
  EXPECT_DOUBLE_EQ(square(Eigen::Vector2d(0.5, 0.7)), 0.25);
  c.setZero();
  c[4] = 1.0;  // u0 u1
  const Polynomial2d cross(2, Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(2.0, 4.0), c);
  EXPECT_DOUBLE_EQ(cross(Eigen::Vector2d(2.0, 4.0)), 0.5 * 0.5);
}

TEST(Polynomial2d, VoltsAndMillivoltsGiveTheSameValues) {
  // The same data in millivolts: normalisation maps both to the same [-1, 1] square, so the
  // fits agree to rounding; without it the degree-5 columns would be 1e15 apart.
  const std::vector<Eigen::Vector2d> volts = Grid(13, -10.0, 10.0);
  std::vector<Eigen::Vector2d> millivolts;
  for (const Eigen::Vector2d& v : volts) millivolts.push_back(1000.0 * v);
  const Polynomial2d f_v = Polynomial2d::Fit(volts, Values(volts), 5);
  const Polynomial2d f_mv = Polynomial2d::Fit(millivolts, Values(volts), 5);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector2d v{u(rng), u(rng)};
    const double a = f_v(v), b = f_mv(1000.0 * v);
    EXPECT_NEAR(a, b, 1e-12 * std::max(1.0, std::abs(a))) << v.transpose();
  }
}

TEST(Polynomial2d, NearZeroAndOffsetInputsStayAccurate) {
  // Microvolt-sized inputs around zero, and a 20 mV span riding on a 1 kV offset: both
  // normalise to the unit square, so the fit is as good as the inputs. (The offset inputs
  // keep only 11 of their 16 digits of spread, which bounds the second case to ~1e-10.)
  for (const auto& [centre, half, tolerance] :
       {std::tuple{0.0, 1e-6, 1e-12}, std::tuple{1000.0, 0.01, 1e-9}}) {
    std::vector<Eigen::Vector2d> x;
    std::vector<double> y;
    for (const Eigen::Vector2d& g : Grid(9, -1.0, 1.0)) {
      x.push_back(Eigen::Vector2d::Constant(centre) + half * g);
      y.push_back(Known(10.0 * g));  // a degree-5 polynomial of the normalised input
    }
    const Polynomial2d f = Polynomial2d::Fit(x, y, 5);
    for (std::size_t k = 0; k < x.size(); k += 7) {
      EXPECT_NEAR(f(x[k]), y[k], tolerance) << "centre " << centre << " half " << half;
    }
  }
}

TEST(Polynomial2d, UnevenButSpreadDataStayWellConditioned) {
  // 95 % of the points crowd the middle 2 % of the range (a calibration that dwelt near zero
  // volts); the rest cover it. The range still fixes the normalisation, so the fit is exact.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> narrow(-0.1, 0.1), wide(-10.0, 10.0);
  std::vector<Eigen::Vector2d> x;
  for (int k = 0; k < 950; ++k) x.push_back({narrow(rng), narrow(rng)});
  for (int k = 0; k < 50; ++k) x.push_back({wide(rng), wide(rng)});
  const Polynomial2d f = Polynomial2d::Fit(x, Values(x), 5);
  for (const Eigen::Vector2d& v : Grid(7, -10.0, 10.0)) EXPECT_NEAR(f(v), Known(v), 1e-9);
}

TEST(Polynomial2d, ClusteredInputsFailClearly) {
  // Four tight clumps: 4 distinct places cannot fix 21 coefficients, whatever the count.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> jitter(0.0, 1e-7);
  std::vector<Eigen::Vector2d> clumps;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(-5, -5), Eigen::Vector2d(5, -5),
                                   Eigen::Vector2d(-5, 5), Eigen::Vector2d(5, 5)}) {
    for (int k = 0; k < 50; ++k) clumps.push_back(c + Eigen::Vector2d{jitter(rng), jitter(rng)});
  }
  const std::string clumped = FitError(clumps, Values(clumps), 5);
  EXPECT_NE(clumped.find("condition number"), std::string::npos) << clumped;
  EXPECT_NE(clumped.find("degree 5"), std::string::npos) << clumped;

  // Points on a line spread in both coordinates: the polynomial is fixed only along the line.
  std::vector<Eigen::Vector2d> line;
  for (int k = 0; k < 100; ++k) line.emplace_back(-10.0 + 0.2 * k, 3.0 - 0.1 * k);
  const std::string collinear = FitError(line, Values(line), 5);
  EXPECT_NE(collinear.find("condition number"), std::string::npos) << collinear;

  // The same line is enough for degree 0, which needs no spread at all.
  EXPECT_NO_THROW(Polynomial2d::Fit(line, Values(line), 0));
}

TEST(Polynomial2d, RejectsBadInput) {
  const std::vector<Eigen::Vector2d> x = Grid(4, -1.0, 1.0);  // 16 points
  std::vector<double> y = Values(x);
  EXPECT_NE(FitError(x, y, 5).find("at least 21 points, got 16"), std::string::npos);
  EXPECT_NE(FitError(x, std::span<const double>(y).first(15), 2).find("16 inputs but 15"),
            std::string::npos);
  y[3] = std::nan("");
  EXPECT_NE(FitError(x, y, 2).find("point 3 is not finite"), std::string::npos);
  const std::vector<Eigen::Vector2d> flat(30, Eigen::Vector2d(1.0, 2.0));
  EXPECT_NE(FitError(flat, std::vector<double>(30, 1.0), 1).find("do not vary along axis 0"),
            std::string::npos);
  EXPECT_NE(FitError(x, Values(x), 11).find("degree must be in [0, 10]"), std::string::npos);
  EXPECT_THROW(
      Polynomial2d(2, Eigen::Vector2d::Zero(), Eigen::Vector2d(1.0, 0.0), Eigen::VectorXd::Zero(6)),
      Error);
  EXPECT_THROW(
      Polynomial2d(2, Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones(), Eigen::VectorXd::Zero(5)),
      Error);
}

}  // namespace
}  // namespace uwscan::scanner
