#include "perception/recognition/free_directions.hpp"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
constexpr double kPi = std::numbers::pi;
const Matrix6d kNoSpread = Matrix6d::Zero();

struct Surface {
  std::vector<Eigen::Vector3d> points, normals;
  Eigen::Vector3d Centroid() const {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) c += p;
    return c / static_cast<double>(points.size());
  }
};

// The point-to-plane information of pairs on an exact surface: rows [(x - c) x n, n].
Matrix6d Information(const Surface& s, const Eigen::Vector3d& centre) {
  Matrix6d info = Matrix6d::Zero();
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    Vector6d row;
    row << (s.points[i] - centre).cross(s.normals[i]), s.normals[i];
    info += row * row.transpose();
  }
  return info;
}

double DistanceToLine(const Eigen::Vector3d& p, const Eigen::Vector3d& on_line,
                      const Eigen::Vector3d& axis) {
  const Eigen::Vector3d d = p - on_line;
  return (d - d.dot(axis.normalized()) * axis.normalized()).norm();
}

std::vector<FreeDirection> Of(const PoseConstraints& c, FreeMotion motion) {
  std::vector<FreeDirection> out;
  for (const FreeDirection& f : c.free_O) {
    EXPECT_EQ(f.kind, FreeKind::kUnconstrained);
    if (f.motion == motion) out.push_back(f);
  }
  return out;
}

// Half a pipe's circumference, no ends: it slides along its axis and rolls about it.
TEST(FreeDirections, APipeWithoutEndsSlidesAndRollsAboutItsOwnAxis) {
  const Eigen::Vector3d on_axis(0.2, -0.1, 0.5);
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 1.0, 0.0).normalized();
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ(), third = axis.cross(across);
  Surface pipe;
  for (int i = 0; i < 60; ++i) {
    for (int k = 0; k <= 30; ++k) {
      const double angle = kPi * k / 30.0;
      const Eigen::Vector3d normal = std::cos(angle) * across + std::sin(angle) * third;
      pipe.normals.push_back(normal);
      pipe.points.push_back(on_axis + (-0.2 + 0.4 * i / 59.0) * axis + 0.1 * normal);
    }
  }
  const Eigen::Vector3d centre = pipe.Centroid();  // off the axis: half the circumference
  const PoseConstraints c =
      AnalysePoseConstraints(Information(pipe, centre), kNoSpread, centre, 5e-4, 0.2, 1e-3);
  ASSERT_EQ(c.free_O.size(), 2u);
  const auto slides = Of(c, FreeMotion::kTranslation), rolls = Of(c, FreeMotion::kRotation);
  ASSERT_EQ(slides.size(), 1u);
  ASSERT_EQ(rolls.size(), 1u);
  EXPECT_NEAR(std::abs(slides[0].axis_S.dot(axis)), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(rolls[0].axis_S.dot(axis)), 1.0, 1e-9);
  EXPECT_LT(DistanceToLine(rolls[0].point_S, on_axis, axis), 1e-9);
  // Nothing else is loose, and the free directions carry no covariance.
  EXPECT_EQ((c.covariance.bottomRightCorner<3, 3>() * axis).norm() < 1e-12, true);

  // A floor adds its variance along every pinned direction, a rotation's at the radius, and
  // nothing along the free ones. (The roll, about the axis off the centre, moves the centre along
  // `across`; the shift along `third` and the tilt about `across` are pinned and apart from it.)
  const double floor_m = 1e-4, radius_m = 0.2;
  const PoseConstraints floored = AnalysePoseConstraints(Information(pipe, centre), kNoSpread,
                                                         centre, 5e-4, radius_m, 1e-3, floor_m);
  ASSERT_EQ(floored.free_O.size(), 2u);
  const Matrix6d added = floored.covariance - c.covariance;
  Vector6d shift, tilt, slide;
  shift << 0, 0, 0, third;
  tilt << across, 0, 0, 0;
  slide << 0, 0, 0, axis;
  EXPECT_NEAR(shift.dot(added * shift), floor_m * floor_m, 1e-15);
  EXPECT_NEAR(tilt.dot(added * tilt), floor_m * floor_m / (radius_m * radius_m), 1e-15);
  EXPECT_LT(std::abs(slide.dot(floored.covariance * slide)), 1e-15);
  EXPECT_THROW(AnalysePoseConstraints(Information(pipe, centre), kNoSpread, centre, 5e-4, radius_m,
                                      1e-3, -1e-4),
               Error);
}

// A 90-degree elbow seen without its ends turns about its bend axis, and only about it: the
// arc is long enough to pin the tube's roll.
TEST(FreeDirections, AnElbowWithoutEndsTurnsAboutItsBendAxis) {
  const double bend = 0.3, tube = 0.05;
  const Eigen::Vector3d bend_centre(-0.1, 0.4, 0.2);
  Surface elbow;
  for (int i = 0; i <= 90; ++i) {
    const double phi = (-45.0 + i) * kPi / 180.0;
    const Eigen::Vector3d radial(std::cos(phi), std::sin(phi), 0.0);
    for (int k = 0; k < 72; ++k) {
      const double psi = 2.0 * kPi * k / 72.0;
      const Eigen::Vector3d normal =
          std::cos(psi) * radial + std::sin(psi) * Eigen::Vector3d::UnitZ();
      elbow.normals.push_back(normal);
      elbow.points.push_back(bend_centre + bend * radial + tube * normal);
    }
  }
  const Eigen::Vector3d centre = elbow.Centroid();
  const PoseConstraints c =
      AnalysePoseConstraints(Information(elbow, centre), kNoSpread, centre, 1e-4, 0.2, 1e-3);
  ASSERT_EQ(c.free_O.size(), 1u);
  const FreeDirection& turn = c.free_O[0];
  EXPECT_EQ(turn.motion, FreeMotion::kRotation);
  EXPECT_NEAR(std::abs(turn.axis_S.z()), 1.0, 1e-9);
  EXPECT_LT(DistanceToLine(turn.point_S, bend_centre, Eigen::Vector3d::UnitZ()), 1e-9);
}

// Two rotations about skew axes left free, as an information with that null space: the two axes
// come back, not a mixture of them.
TEST(FreeDirections, TwoFreeRotationsComeBackAboutTheirOwnAxes) {
  const double radius = 0.25;
  const Eigen::Vector3d centre(0.02, 0.03, -0.01);
  const Eigen::Vector3d point_a(0.1, 0.0, 0.0), axis_a = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d point_b(0.0, 0.2, 0.05),
      axis_b = Eigen::Vector3d(1.0, 0.0, 0.3).normalized();
  const auto twist = [&](const Eigen::Vector3d& point, const Eigen::Vector3d& axis) {
    Vector6d t;  // scaled: rotation in metres at the radius
    t << radius * axis, axis.cross(centre - point);
    return t;
  };
  Eigen::Matrix<double, 6, 8> spanning;
  spanning << twist(point_a, axis_a), twist(point_b, axis_b), Matrix6d::Identity();
  const Eigen::HouseholderQR<Eigen::Matrix<double, 6, 8>> qr(spanning);
  const Matrix6d q = qr.householderQ();
  Matrix6d scaled = Matrix6d::Zero();
  for (int k = 2; k < 6; ++k) scaled += 100.0 * k * q.col(k) * q.col(k).transpose();
  Matrix6d D_inverse = Matrix6d::Identity();
  D_inverse.topLeftCorner<3, 3>() *= radius;
  const Matrix6d information = D_inverse * scaled * D_inverse;

  const PoseConstraints c =
      AnalysePoseConstraints(information, kNoSpread, centre, 1e-3, radius, 1e-3);
  const auto rotations = Of(c, FreeMotion::kRotation);
  ASSERT_EQ(c.free_O.size(), 2u);
  ASSERT_EQ(rotations.size(), 2u);
  for (const auto& [point, axis] : {std::pair(point_a, axis_a), std::pair(point_b, axis_b)}) {
    int found = 0;
    for (const FreeDirection& r : rotations) {
      found += std::abs(r.axis_S.dot(axis)) > 1.0 - 1e-9 &&
               DistanceToLine(r.point_S, point, axis) < 1e-9;
    }
    EXPECT_EQ(found, 1) << "axis " << axis.transpose();
  }
}

// A flat patch: it slides both ways in its plane and turns about its normal.
TEST(FreeDirections, APlaneSlidesInItselfAndTurnsAboutItsNormal) {
  Surface plane;
  for (int i = 0; i < 20; ++i) {
    for (int k = 0; k < 20; ++k) {
      plane.points.emplace_back(0.01 * i, 0.01 * k, 0.3);
      plane.normals.emplace_back(0.0, 0.0, 1.0);
    }
  }
  const Eigen::Vector3d centre = plane.Centroid();
  const PoseConstraints c =
      AnalysePoseConstraints(Information(plane, centre), kNoSpread, centre, 1e-4, 0.1, 1e-3);
  const auto slides = Of(c, FreeMotion::kTranslation), turns = Of(c, FreeMotion::kRotation);
  ASSERT_EQ(slides.size(), 2u);
  ASSERT_EQ(turns.size(), 1u);
  for (const FreeDirection& s : slides) EXPECT_LT(std::abs(s.axis_S.z()), 1e-9);
  EXPECT_NEAR(std::abs(turns[0].axis_S.z()), 1.0, 1e-9);
}

// Three faces of a box pin everything; the covariance is then sigma^2 times the inverse.
TEST(FreeDirections, ABoxCornerIsPinnedAndItsCovarianceIsTheInverse) {
  Surface corner;
  for (int i = 0; i < 15; ++i) {
    for (int k = 0; k < 15; ++k) {
      const double a = 0.01 * i, b = 0.01 * k;
      corner.points.emplace_back(a, b, 0.0), corner.normals.emplace_back(0.0, 0.0, 1.0);
      corner.points.emplace_back(a, 0.0, b), corner.normals.emplace_back(0.0, 1.0, 0.0);
      corner.points.emplace_back(0.0, a, b), corner.normals.emplace_back(1.0, 0.0, 0.0);
    }
  }
  const Eigen::Vector3d centre = corner.Centroid();
  const Matrix6d information = Information(corner, centre);
  const double sigma = 3e-4;
  const PoseConstraints c =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, 0.1, 1e-3);
  EXPECT_TRUE(c.free_O.empty());
  const Matrix6d expected = sigma * sigma * information.inverse();
  EXPECT_LT((c.covariance - expected).norm(), 1e-9 * expected.norm());

  // Residuals correlated over patches add the sandwich H^-1 S H^-1.
  Vector6d push;
  push << 0.3, -0.1, 0.2, 1e-3, 2e-3, -1e-3;
  const Matrix6d spread = 1e-8 * push * push.transpose();
  const PoseConstraints patched =
      AnalysePoseConstraints(information, spread, centre, sigma, 0.1, 1.0);
  const Matrix6d sandwich = expected + information.inverse() * spread * information.inverse();
  EXPECT_LT((patched.covariance - sandwich).norm(), 1e-9 * sandwich.norm());
}

// A direction the independent residuals pin but patches of correlated residuals push apart is
// free: its variance is sigma^2 / lambda + u^T S u / lambda^2.
TEST(FreeDirections, ResidualsCorrelatedOverPatchesLoosenTheDirectionTheyPush) {
  const double sigma = 1e-3, tolerance = 2e-3, radius = 0.5;
  Matrix6d information = Matrix6d::Identity() * 1e6;
  const double lambda = 1.0;  // slide along z: std sigma = 1 mm, pinned alone
  information(5, 5) = lambda;
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  EXPECT_TRUE(AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance)
                  .free_O.empty());
  Matrix6d spread = Matrix6d::Zero();
  spread(5, 5) = 4e-6 * lambda * lambda;  // adds (2 mm)^2
  const PoseConstraints c =
      AnalysePoseConstraints(information, spread, centre, sigma, radius, tolerance);
  ASSERT_EQ(c.free_O.size(), 1u);
  EXPECT_EQ(c.free_O[0].motion, FreeMotion::kTranslation);
  EXPECT_NEAR(std::abs(c.free_O[0].axis_S.z()), 1.0, 1e-12);
}

// The tolerance is a standard deviation: a direction known to 0.9 of it is pinned, one known
// to 1.1 of it is free; a rotation's is measured at the radius.
TEST(FreeDirections, TheToleranceIsAStandardDeviationInMetres) {
  const double sigma = 1e-3, tolerance = 2e-3, radius = 0.5;
  const auto information_for = [&](double translation_std_m, double rotation_std_m) {
    Matrix6d info = Matrix6d::Identity() * 1e6;
    info(5, 5) = (sigma / translation_std_m) * (sigma / translation_std_m);
    const double rotation_std_rad = rotation_std_m / radius;
    info(0, 0) = (sigma / rotation_std_rad) * (sigma / rotation_std_rad);
    return info;
  };
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  EXPECT_TRUE(AnalysePoseConstraints(information_for(0.9 * tolerance, 0.9 * tolerance), kNoSpread,
                                     centre, sigma, radius, tolerance)
                  .free_O.empty());
  const PoseConstraints loose =
      AnalysePoseConstraints(information_for(1.1 * tolerance, 1.1 * tolerance), kNoSpread, centre,
                             sigma, radius, tolerance);
  EXPECT_EQ(Of(loose, FreeMotion::kTranslation).size(), 1u);
  EXPECT_EQ(Of(loose, FreeMotion::kRotation).size(), 1u);
}

// Where restarts of the fit come to rest (RestartSpread) adds to the covariance, and a direction
// they leave further off than the tolerance is freed as itself: a slide along x stays a slide
// along x though every eigenvector of the information has a share of it.
TEST(FreeDirections, ADirectionTheFitDoesNotHoldIsFreedAsItself) {
  const double sigma = 1e-3, tolerance = 2e-3, radius = 0.2;
  const Eigen::Vector3d centre(0.1, 0.0, -0.3);
  // An information that pins every direction to about 0.3 um, its eigenvectors mixing them all.
  Matrix6d any;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) any(i, j) = std::sin(7.0 * i + 3.0 * j + 1.0);
  }
  const Matrix6d mix = Eigen::HouseholderQR<Matrix6d>(any).householderQ();
  Vector6d lambda;
  lambda << 11.0, 12.0, 13.0, 14.0, 15.0, 16.0;
  Matrix6d D = Matrix6d::Identity();  // the analysis' scaling: rotations in metres at the radius
  D.topLeftCorner<3, 3>() *= 1.0 / radius;
  const Matrix6d information =
      D.inverse() * (1e6 * mix * lambda.asDiagonal() * mix.transpose()) * D.inverse();
  const PoseConstraints held =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance);
  ASSERT_TRUE(held.free_O.empty());

  Matrix6d small = Matrix6d::Zero();
  small(3, 3) = 1e-3 * 1e-3;  // restarts resting 1 mm off along x: still held
  const PoseConstraints loosened =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance, 0.0, small);
  EXPECT_TRUE(loosened.free_O.empty());
  EXPECT_LT((loosened.covariance - held.covariance - small).norm(), 1e-9 * small.norm());

  Matrix6d flat = Matrix6d::Zero();
  flat(3, 3) = 6e-3 * 6e-3;  // 6 mm: the fit does not hold x
  const PoseConstraints freed =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance, 0.0, flat);
  ASSERT_EQ(freed.free_O.size(), 1u);
  EXPECT_EQ(freed.free_O[0].motion, FreeMotion::kTranslation);
  EXPECT_NEAR(std::abs(freed.free_O[0].axis_S.x()), 1.0, 1e-9);
  EXPECT_LT((freed.covariance * Vector6d::Unit(3)).norm(), 1e-15);
  // Along the rest, what the information says: the covariance restricted to them.
  Matrix6d across = Matrix6d::Identity() - Vector6d::Unit(3) * Vector6d::Unit(3).transpose();
  EXPECT_LT((freed.covariance - across * held.covariance * across).norm(),
            1e-9 * held.covariance.norm());

  // A turn is judged at the radius: 1 mm there is held, 6 mm frees the turn about x, through the
  // centre.
  Matrix6d turn = Matrix6d::Zero();
  turn(0, 0) = (1e-3 / radius) * (1e-3 / radius);
  const PoseConstraints turned =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance, 0.0, turn);
  EXPECT_TRUE(turned.free_O.empty());
  EXPECT_LT((turned.covariance - held.covariance - turn).norm(), 1e-9 * turn.norm());
  turn(0, 0) = (6e-3 / radius) * (6e-3 / radius);
  const PoseConstraints free_turn =
      AnalysePoseConstraints(information, kNoSpread, centre, sigma, radius, tolerance, 0.0, turn);
  ASSERT_EQ(free_turn.free_O.size(), 1u);
  EXPECT_EQ(free_turn.free_O[0].motion, FreeMotion::kRotation);
  EXPECT_NEAR(std::abs(free_turn.free_O[0].axis_S.x()), 1.0, 1e-9);
  EXPECT_LT((free_turn.free_O[0].point_S - centre).norm(), 1e-9);
}

// What the restarts free is what they show: two directions the information pins, each to 0.95
// of the tolerance, whose residual patches push them together (their sum's variance is over the
// tolerance) stay pinned when the restarts all come back, as with no restarts at all.
TEST(FreeDirections, RestartsThatComeBackFreeNothing) {
  const double sigma = 1e-3, tolerance = 2e-3, radius = 0.5;
  const double each = 0.45 * tolerance * tolerance;
  const double lambda = sigma * sigma / each;  // sigma^2 / lambda = 0.45 tolerance^2...
  Matrix6d information = Matrix6d::Identity() * 1e12;
  information(4, 4) = information(5, 5) = lambda;  // ...along the slides in y and z
  Matrix6d spread = Matrix6d::Zero();
  // u^T S u / lambda^2 = 0.45 tolerance^2 more along each, pushing y and z together.
  spread.bottomRightCorner<2, 2>().setConstant(each * lambda * lambda);
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  ASSERT_TRUE(
      AnalysePoseConstraints(information, spread, centre, sigma, radius, tolerance).free_O.empty());
  const Matrix6d tiny = 1e-20 * Matrix6d::Identity();
  EXPECT_TRUE(
      AnalysePoseConstraints(information, spread, centre, sigma, radius, tolerance, 0.0, tiny)
          .free_O.empty());
}

TEST(FreeDirections, BadInputIsRefused) {
  Matrix6d information = Matrix6d::Identity();
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  EXPECT_THROW(AnalysePoseConstraints(information, kNoSpread, centre, 0.0, 0.1, 1e-3), Error);
  EXPECT_THROW(AnalysePoseConstraints(information, kNoSpread, centre, 1e-3, -0.1, 1e-3), Error);
  EXPECT_THROW(AnalysePoseConstraints(information, kNoSpread, centre, 1e-3, 0.1, 0.0), Error);
  information(0, 1) = 1.0;  // not symmetric
  EXPECT_THROW(AnalysePoseConstraints(information, kNoSpread, centre, 1e-3, 0.1, 1e-3), Error);
  information(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(AnalysePoseConstraints(information, kNoSpread, centre, 1e-3, 0.1, 1e-3), Error);
  Matrix6d spread = Matrix6d::Zero();
  spread(2, 3) = 1.0;  // not symmetric
  EXPECT_THROW(AnalysePoseConstraints(Matrix6d::Identity(), spread, centre, 1e-3, 0.1, 1e-3),
               Error);
  EXPECT_THROW(
      AnalysePoseConstraints(Matrix6d::Identity(), kNoSpread, centre, 1e-3, 0.1, 1e-3, 0.0, spread),
      Error);
}

}  // namespace
}  // namespace uwscan::perception
