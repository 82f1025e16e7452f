#include "perception/registration/icp.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "perception/cloud/nearest_grid.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A bumpy, non-symmetric height field over 0.5 m x 0.4 m: three Gaussian bumps and a ripple,
// heights of a few centimetres, so every rigid motion changes the surface.
double Height(double x, double y, Eigen::Vector2d* gradient) {
  struct Bump {
    double x, y, sigma, height;
  };
  constexpr Bump kBumps[] = {
      {0.10, 0.05, 0.05, 0.04}, {-0.12, -0.08, 0.04, 0.03}, {0.05, -0.12, 0.06, -0.025}};
  double z = 0.01 * std::sin(6.0 * x) * std::cos(4.0 * y);
  Eigen::Vector2d g(0.06 * std::cos(6.0 * x) * std::cos(4.0 * y),
                    -0.04 * std::sin(6.0 * x) * std::sin(4.0 * y));
  for (const Bump& b : kBumps) {
    const double dx = x - b.x, dy = y - b.y;
    const double e = b.height * std::exp(-(dx * dx + dy * dy) / (2.0 * b.sigma * b.sigma));
    z += e;
    g += Eigen::Vector2d(-dx, -dy) * e / (b.sigma * b.sigma);
  }
  if (gradient != nullptr) *gradient = g;
  return z;
}

// n random samples of the surface with x in [x_min, 0.25] m, offset by `origin`, normals exact,
// Gaussian noise of sigma_m on the points.
PointCloud BumpySurface(int n, std::uint64_t seed, double x_min = -0.25, double sigma_m = 0.0,
                        const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(x_min, 0.25), uy(-0.2, 0.2);
  std::normal_distribution<double> noise(0.0, sigma_m > 0.0 ? sigma_m : 1.0);
  PointCloud cloud;
  cloud.origin = origin;
  for (int i = 0; i < n; ++i) {
    const double x = ux(rng), y = uy(rng);
    Eigen::Vector2d g;
    Eigen::Vector3d p(x, y, Height(x, y, &g));
    if (sigma_m > 0.0) p += sigma_m * Eigen::Vector3d{noise(rng), noise(rng), noise(rng)};
    cloud.points.push_back(p.cast<float>());
    cloud.normals.push_back(Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized().cast<float>());
  }
  return cloud;
}

// The target's own samples with x > x_min, with Gaussian noise of sigma_m added, normals
// dropped (the source needs none).
PointCloud SubsetWithNoise(const PointCloud& target, double x_min, double sigma_m,
                           std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  PointCloud out;
  out.origin = target.origin;
  for (const Eigen::Vector3f& p : target.points) {
    if (p.x() <= x_min) continue;
    const Eigen::Vector3d n{noise(rng), noise(rng), noise(rng)};
    out.points.push_back(p + n.cast<float>());
  }
  return out;
}

// 5 degrees about a skew axis and 2 cm.
Eigen::Isometry3d KnownMotion() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  T.translation() = 0.02 * Eigen::Vector3d(0.6, -0.8, 0.0);
  return T;
}

double RotationErrorRad(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}
double TranslationErrorM(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

IcpOptions Options(IcpMethod method) {
  IcpOptions options;
  options.method = method;
  return options;
}

class IcpMethods : public ::testing::TestWithParam<IcpMethod> {};

INSTANTIATE_TEST_SUITE_P(Icp, IcpMethods,
                         ::testing::Values(IcpMethod::kPointToPoint, IcpMethod::kPointToPlane),
                         [](const ::testing::TestParamInfo<IcpMethod>& info) {
                           return std::string(info.param == IcpMethod::kPointToPoint
                                                  ? "PointToPoint"
                                                  : "PointToPlane");
                         });

// The source is the target's own samples (every other one) seen from a frame moved by the
// known motion: the exact answer is reachable.
TEST_P(IcpMethods, RecoversAKnownMotionWithoutNoise) {
  const PointCloud target = BumpySurface(6000, 1);
  PointCloud half;
  for (std::size_t i = 0; i < target.size(); i += 2) half.points.push_back(target.points[i]);
  const Eigen::Isometry3d truth = KnownMotion();
  const PointCloud source = Transformed(half, truth.inverse());
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), Options(GetParam()));
  EXPECT_TRUE(result.converged);
  EXPECT_LT(RotationErrorRad(result.T_target_source, truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(result.T_target_source, truth), 1e-3);
  // In fact to float precision.
  EXPECT_LT(RotationErrorRad(result.T_target_source, truth), 1e-5);
  EXPECT_LT(TranslationErrorM(result.T_target_source, truth), 1e-6);
  EXPECT_DOUBLE_EQ(result.fitness, 1.0);
  EXPECT_LT(result.inlier_rmse, 1e-6);
  EXPECT_GT(result.iterations, 1);
}

// The target's samples with x > 0 (60 % of it), 0.5 mm noise on the source.
TEST_P(IcpMethods, RecoversAKnownMotionWithNoiseAndPartialOverlap) {
  const PointCloud target = BumpySurface(8000, 2);
  const Eigen::Isometry3d truth = KnownMotion();
  const PointCloud source = Transformed(SubsetWithNoise(target, 0.0, 0.0005, 3), truth.inverse());
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), Options(GetParam()));
  EXPECT_TRUE(result.converged);
  // Measured: point-to-point 0.005 deg / 0.01 mm (it pairs each point with its own sample),
  // point-to-plane 0.04-0.06 deg / 0.1 mm (only the normal component of the noise averages out,
  // and rotation about the mean normal is constrained by the slopes alone).
  EXPECT_LT(RotationErrorRad(result.T_target_source, truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(result.T_target_source, truth), 1e-3);
  EXPECT_GT(result.fitness, 0.99);
  EXPECT_LT(result.inlier_rmse, 0.0012);
}

// Independent samplings of source and target, both noisy, partial overlap: point-to-plane
// finds the surface itself. (Point-to-point pairs samples, not surfaces: with 4.5 mm spacing it
// stops at a fixed point of its pairing ~2 deg from the truth on this smooth surface, and
// crawls there over hundreds of iterations when denser; not tested as a success.)
TEST(IcpPointToPlane, IndependentSamplesWithNoiseAndPartialOverlap) {
  const PointCloud target = BumpySurface(8000, 2, -0.25, 0.0005);
  const Eigen::Isometry3d truth = KnownMotion();
  const PointCloud source = Transformed(BumpySurface(4000, 3, 0.0, 0.0005), truth.inverse());
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), Options(IcpMethod::kPointToPlane));
  EXPECT_TRUE(result.converged);
  EXPECT_LT(RotationErrorRad(result.T_target_source, truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(result.T_target_source, truth), 1e-3);
  EXPECT_GT(result.fitness, 0.99);
  EXPECT_LT(result.inlier_rmse, 0.005);
}

TEST_P(IcpMethods, IdenticalWithOneAndTwoThreads) {
  const PointCloud target = BumpySurface(10000, 4, -0.25, 0.0005);
  const PointCloud source =
      Transformed(BumpySurface(6000, 5, -0.1, 0.0005), KnownMotion().inverse());
  IcpOptions options = Options(GetParam());
  options.threads = 1;
  const RegistrationResult one = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  options.threads = 2;
  const RegistrationResult two = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  // And through OpenMP's default.
  options.threads = 0;
  const int saved_threads = omp_get_max_threads();
  omp_set_num_threads(2);
  const RegistrationResult two_default =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  omp_set_num_threads(saved_threads);
  for (const RegistrationResult* other : {&two, &two_default}) {
    EXPECT_TRUE(one.T_target_source.matrix() == other->T_target_source.matrix());
    EXPECT_EQ(one.fitness, other->fitness);
    EXPECT_EQ(one.inlier_rmse, other->inlier_rmse);
    EXPECT_EQ(one.iterations, other->iterations);
    EXPECT_EQ(one.converged, other->converged);
    EXPECT_TRUE(one.information == other->information);
  }
}

// A target prepared once gives the same bits as AlignIcp on the cloud, start after start, and so
// does one searched through a grid (NearestGrid) at the stages within its radius.
TEST_P(IcpMethods, APreparedTargetGivesTheSameAnswerForEveryStart) {
  const PointCloud target = BumpySurface(8000, 4, -0.25, 0.0005);
  const PointCloud source =
      Transformed(BumpySurface(3000, 5, -0.1, 0.0005), KnownMotion().inverse());
  const IcpTarget prepared(target);
  const IcpTarget gridded(target, 0.02);              // the last two of the three stages
  const IcpTarget fine_gridded(target, 0.05, 0.002);  // every stage, on small cells
  EXPECT_EQ(prepared.grid(), nullptr);
  ASSERT_NE(gridded.grid(), nullptr);
  EXPECT_EQ(gridded.grid()->max_radius_m(), 0.02);
  ASSERT_NE(fine_gridded.grid(), nullptr);
  EXPECT_EQ(fine_gridded.grid()->max_radius_m(), 0.05);
  const IcpOptions options = Options(GetParam());
  for (const double angle_deg : {0.0, 3.0, -4.0}) {
    Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
    start.linear() = Eigen::AngleAxisd(angle_deg * kDeg, Eigen::Vector3d::UnitZ()).matrix();
    const RegistrationResult plain = AlignIcp(source, target, start, options);
    for (const IcpTarget* reused_target : {&prepared, &gridded, &fine_gridded}) {
      const RegistrationResult reused = AlignIcp(source, *reused_target, start, options);
      EXPECT_TRUE(plain.T_target_source.matrix() == reused.T_target_source.matrix());
      EXPECT_EQ(plain.fitness, reused.fitness);
      EXPECT_EQ(plain.iterations, reused.iterations);
      EXPECT_TRUE(plain.information == reused.information);
      EXPECT_LT(TranslationErrorM(reused.T_target_source, KnownMotion()),
                0.005);  // independent samples
    }
  }
  EXPECT_THROW(IcpTarget(target, -0.01), Error);
  EXPECT_THROW(IcpTarget(target, 0.01, 0.02), Error);  // cells wider than the radius
  PointCloud two_points;
  two_points.points = {Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX()};
  EXPECT_THROW(IcpTarget target(two_points), Error);
}

// Moving both clouds (and the start) by M moves the answer by M: T' = M T M^-1.
TEST_P(IcpMethods, InvariantToARigidMotionOfBothInputs) {
  const PointCloud target = BumpySurface(6000, 6);
  const Eigen::Isometry3d truth = KnownMotion();
  const PointCloud source = Transformed(SubsetWithNoise(target, -0.05, 0.0005, 7), truth.inverse());
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = Eigen::AngleAxisd(2.0, Eigen::Vector3d(-0.3, 0.5, 0.8).normalized()).matrix();
  M.translation() = Eigen::Vector3d(12.0, -40.0, 7.5);
  const Eigen::Isometry3d init = Eigen::Isometry3d::Identity();
  const RegistrationResult plain = AlignIcp(source, target, init, Options(GetParam()));
  const RegistrationResult moved = AlignIcp(Transformed(source, M), Transformed(target, M),
                                            M * init * M.inverse(), Options(GetParam()));
  // Compared in the unmoved frames, so M's 40 m lever arm does not scale rounding differences.
  const Eigen::Isometry3d moved_back = M.inverse() * moved.T_target_source * M;
  EXPECT_LT(RotationErrorRad(moved_back, plain.T_target_source), 1e-6);
  EXPECT_LT(TranslationErrorM(moved_back, plain.T_target_source), 1e-6);
  EXPECT_TRUE(plain.converged);
  EXPECT_LT(RotationErrorRad(plain.T_target_source, truth), 0.1 * kDeg);
  EXPECT_NEAR(moved.fitness, plain.fitness, 1e-3);
  EXPECT_NEAR(moved.inlier_rmse, plain.inlier_rmse, 1e-6);
  EXPECT_EQ(moved.converged, plain.converged);
}

// The target 1e6 m from its frame's origin, the source in a vehicle frame near 0 (origins 1e6 m
// apart): the answer is as good as for nearby clouds.
TEST_P(IcpMethods, HugeCoordinatesAlignAsWellAsSmallOnes) {
  const Eigen::Vector3d far(1e6, -2e6, 350.0);
  const Eigen::Isometry3d truth = KnownMotion();
  Eigen::Isometry3d T_V_S = Eigen::Isometry3d::Identity();  // source sensor in a vehicle frame
  T_V_S.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.1, 0.9, -0.2).normalized()).matrix();
  T_V_S.translation() = Eigen::Vector3d(1.5, -0.4, 3.0);
  const PointCloud small_target = BumpySurface(6000, 8);
  const PointCloud huge_target = BumpySurface(6000, 8, -0.25, 0.0, far);
  const PointCloud source =
      Transformed(SubsetWithNoise(small_target, -0.1, 0.0005, 9), T_V_S * truth.inverse());
  const Eigen::Isometry3d small_truth = truth * T_V_S.inverse();
  const Eigen::Isometry3d huge_truth = Eigen::Translation3d(far) * small_truth;
  const RegistrationResult small =
      AlignIcp(source, small_target, T_V_S.inverse(), Options(GetParam()));
  const RegistrationResult huge = AlignIcp(
      source, huge_target, Eigen::Translation3d(far) * T_V_S.inverse(), Options(GetParam()));
  EXPECT_TRUE(huge.converged);
  EXPECT_LT(RotationErrorRad(huge.T_target_source, huge_truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(huge.T_target_source, huge_truth), 1e-3);
  EXPECT_NEAR(RotationErrorRad(huge.T_target_source, huge_truth),
              RotationErrorRad(small.T_target_source, small_truth), 1e-7);
  EXPECT_NEAR(TranslationErrorM(huge.T_target_source, huge_truth),
              TranslationErrorM(small.T_target_source, small_truth), 1e-7);
  EXPECT_EQ(huge.fitness, small.fitness);
  EXPECT_NEAR(huge.inlier_rmse, small.inlier_rmse, 1e-9);
}

TEST_P(IcpMethods, NoOverlapIsNotConverged) {
  const PointCloud target = BumpySurface(2000, 10);
  PointCloud source = BumpySurface(2000, 11);
  source.origin = Eigen::Vector3d(5.0, 0.0, 0.0);  // 5 m away, far beyond every stage
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), Options(GetParam()));
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.fitness, 0.0);
  EXPECT_EQ(result.iterations, 0);
  EXPECT_TRUE(result.T_target_source.isApprox(Eigen::Isometry3d::Identity()));
}

// A line has no orientation about itself: never a crash or NaN.
TEST_P(IcpMethods, CollinearCloudsGiveAFiniteAnswer) {
  PointCloud line;
  for (int i = 0; i < 100; ++i) {
    line.points.emplace_back(0.01f * static_cast<float>(i), 0.0f, 0.0f);
    line.normals.emplace_back(0.0f, 0.0f, 1.0f);
  }
  PointCloud source = line;
  source.origin = Eigen::Vector3d(0.0, 0.002, 0.001);
  const RegistrationResult result =
      AlignIcp(source, line, Eigen::Isometry3d::Identity(), Options(GetParam()));
  EXPECT_TRUE(result.T_target_source.matrix().allFinite());
  EXPECT_TRUE(result.information.allFinite());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(result.information);
  EXPECT_LT(solver.eigenvalues()(0), 1e-9 * solver.eigenvalues()(5));
  if (GetParam() == IcpMethod::kPointToPoint) {
    EXPECT_FALSE(result.converged);
  }
}

// Point-to-plane on one plane: the information has exactly three near-zero eigenvalues, whose
// eigenvectors span the two in-plane translations and the rotation about the normal; the
// normal offset is recovered and the unconstrained directions do not move.
TEST(IcpSinglePlane, InformationShowsTheThreeUnconstrainedDirections) {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal();
  const Eigen::Vector3d w = normal.cross(u);
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  PointCloud target;
  target.origin = Eigen::Vector3d(0.5, 0.2, -0.1);
  for (int i = 0; i < 3000; ++i) {
    // The plane passes 0.4 m from the origin, so the rotation-translation coupling is tested.
    const double along_u = uniform(rng), along_w = uniform(rng);
    const Eigen::Vector3d p = 0.4 * normal + along_u * u + along_w * w;
    target.points.push_back(p.cast<float>());
    target.normals.push_back(normal.cast<float>());
  }
  PointCloud source = target;
  source.normals.clear();
  source.origin += 0.004 * normal + 0.01 * u;  // off the plane by 4 mm, slid by 1 cm
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  EXPECT_TRUE(result.converged);
  // The normal offset is removed, the slide is not seen and not "corrected".
  const Eigen::Vector3d t = result.T_target_source.translation();
  EXPECT_NEAR(t.dot(normal), -0.004, 1e-6);
  EXPECT_NEAR(t.dot(u), 0.0, 1e-6);
  EXPECT_NEAR(t.dot(w), 0.0, 1e-6);
  EXPECT_LT(Eigen::AngleAxisd(result.T_target_source.linear()).angle(), 1e-6);

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(result.information);
  const Eigen::Matrix<double, 6, 1> values = solver.eigenvalues();
  EXPECT_LT(values(2), 1e-9 * values(5));
  EXPECT_GT(values(3), 1e-3 * values(5));
  Eigen::Matrix<double, 6, 3> weak = Eigen::Matrix<double, 6, 3>::Zero();
  weak.col(0).head<3>() = normal;  // rotation about the normal
  weak.col(1).tail<3>() = u;       // in-plane translations
  weak.col(2).tail<3>() = w;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Matrix<double, 6, 1> e = solver.eigenvectors().col(k);
    EXPECT_LT((e - weak * (weak.transpose() * e)).norm(), 1e-6) << "eigenvector " << k;
  }
}

TEST(IcpSinglePlane, APriorDecidesTheDirectionsThePlaneLeavesFree) {
  // A plane z = 0.4 m (in the target frame, origin 0); the source is the same plane lifted by
  // 5 mm and slid. The prior says: slid by (0.02, -0.01) m and turned 0.01 rad about z, and
  // also (wrongly) lifted by 1 cm; the points must win along the normal, the prior elsewhere.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  PointCloud target;
  for (int i = 0; i < 3000; ++i) {
    target.points.push_back({float(uniform(rng)), float(uniform(rng)), 0.4f});
    target.normals.emplace_back(0.0f, 0.0f, 1.0f);
  }
  PointCloud source = target;
  source.normals.clear();
  source.origin = Eigen::Vector3d(0.0, 0.0, 0.005);
  IcpPrior prior;
  prior.T_target_source =
      Eigen::Translation3d(0.02, -0.01, 0.01) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ());
  prior.information = Eigen::Matrix<double, 6, 6>::Identity() * 1e4;  // 1 cm, 0.01 rad
  prior.point_sigma_m = 0.0005;
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.prior = prior;
  const RegistrationResult result =
      AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  EXPECT_TRUE(result.converged);
  const Eigen::Isometry3d& T = result.T_target_source;
  EXPECT_NEAR(T.translation().x(), 0.02, 1e-6);   // free: the prior's
  EXPECT_NEAR(T.translation().y(), -0.01, 1e-6);  // free: the prior's
  EXPECT_NEAR(Eigen::AngleAxisd(T.linear()).angle(), 0.01, 1e-6);
  // Along the normal 3000 points at 0.5 mm outweigh a 1 cm prior: the surfaces meet.
  EXPECT_NEAR((T * Eigen::Vector3d(0.0, 0.0, 0.405)).z(), 0.4, 2e-5);

  options.method = IcpMethod::kPointToPoint;
  EXPECT_THROW(options.Check(), Error);
  options.method = IcpMethod::kPointToPlane;
  options.prior->information(0, 1) = 1.0;  // not symmetric
  EXPECT_THROW(options.Check(), Error);
}

// A pipe's wall sampled on both faces with outward normals (the outer face's away from the
// axis, the bore's towards it), and a scan of its top from a sensor above, normals towards it.
PointCloud PipeWalls(double outer_m, double inner_m, double length_m) {
  std::vector<Eigen::Vector3d> points;
  PointCloud cloud;
  for (const double radius : {outer_m, inner_m}) {
    const int around = static_cast<int>(2.0 * std::numbers::pi * radius / 0.003);
    for (int i = 0; i < around; ++i) {
      const double a = 2.0 * std::numbers::pi * i / around;
      const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
      for (double z = -0.5 * length_m; z <= 0.5 * length_m; z += 0.003) {
        points.push_back(radius * radial + Eigen::Vector3d(0, 0, z));
        cloud.normals.push_back((radius == outer_m ? radial : -radial).cast<float>());
      }
    }
  }
  const PointCloud made = MakeCloud(points);
  cloud.origin = made.origin;
  cloud.points = made.points;
  return cloud;
}

PointCloud PipeTopScan(double outer_m, double length_m) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;
  for (double a = 0.25 * std::numbers::pi; a <= 0.75 * std::numbers::pi; a += 0.05) {
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
    for (double z = -0.4 * length_m; z <= 0.4 * length_m; z += 0.004) {
      points.push_back(outer_m * radial + Eigen::Vector3d(0, 0, z));
      normals.push_back(radial.cast<float>());
    }
  }
  PointCloud cloud = MakeCloud(points);
  cloud.normals = normals;
  return cloud;
}

TEST(IcpNormalGate, KeepsAScanOfAPipesOutsideOffItsBore) {
  const double outer = 0.05, inner = 0.045, length = 0.3;
  const PointCloud model = PipeWalls(outer, inner, length);
  const PointCloud scan = PipeTopScan(outer, length);
  // Started a wall's thickness too low, the scan lies on the bore, where the point-to-plane
  // distances are as small as on the outside.
  const Eigen::Isometry3d start(Eigen::Translation3d(0.0, -(outer - inner), 0.0));
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.max_correspondence_distance_m = {0.01, 0.0075};
  auto mean_radius = [&](const RegistrationResult& r) {
    double sum = 0.0;
    for (std::size_t i = 0; i < scan.size(); ++i)
      sum += (r.T_target_source * scan.Point(i)).head<2>().norm();
    return sum / static_cast<double>(scan.size());
  };
  const RegistrationResult ungated = AlignIcp(scan, model, start, options);
  EXPECT_LT(mean_radius(ungated), inner + 0.001);  // the trap the gate is for
  options.max_normal_angle_rad = 60.0 * kDeg;
  const RegistrationResult gated = AlignIcp(scan, model, start, options);
  EXPECT_NEAR(mean_radius(gated), outer, 2e-4);
  EXPECT_TRUE(gated.converged);
  EXPECT_GT(gated.fitness, 0.99);
  // The grid search honours the gate as the tree does: the same bits.
  const RegistrationResult gridded = AlignIcp(scan, IcpTarget(model, 0.01), start, options);
  EXPECT_TRUE(gridded.T_target_source.matrix() == gated.T_target_source.matrix());
  EXPECT_EQ(gridded.iterations, gated.iterations);
}

TEST(IcpNormalGate, NeedsNormalsOnBothClouds) {
  const PointCloud model = PipeWalls(0.05, 0.045, 0.3);
  PointCloud scan = PipeTopScan(0.05, 0.3);
  scan.normals.clear();
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.max_normal_angle_rad = 1.0;
  try {
    AlignIcp(scan, model, Eigen::Isometry3d::Identity(), options);
    ADD_FAILURE() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("max_normal_angle_rad"), std::string::npos);
  }
  options.max_normal_angle_rad = 4.0;
  EXPECT_THROW(options.Check(), Error);
}

// A scan of a 50 mm pipe on the model of a 70 mm one (a wrong object): point-to-plane ICP hops
// between fits until its cap. With stall_iterations it stops and keeps its lowest residual.
TEST(IcpStall, AWrongModelStopsCyclingAtItsLowestResidual) {
  const PointCloud scan = PipeTopScan(0.05, 0.3);
  const PointCloud wrong_model = PipeWalls(0.07, 0.065, 0.3);
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.max_correspondence_distance_m = {0.02};
  options.max_iterations = options.max_iterations_per_stage = 200;
  options.rotation_tolerance_rad = options.translation_tolerance_m = 0.0;
  options.relative_rmse_tolerance = 1e-9;
  const RegistrationResult cycling =
      AlignIcp(scan, wrong_model, Eigen::Isometry3d::Identity(), options);
  EXPECT_EQ(cycling.iterations, 200);  // the trap: the whole cap spent
  EXPECT_FALSE(cycling.converged);
  options.stall_iterations = 10;
  const RegistrationResult stalled =
      AlignIcp(scan, wrong_model, Eigen::Isometry3d::Identity(), options);
  EXPECT_LT(stalled.iterations, 40);
  EXPECT_FALSE(stalled.converged);  // stopping is not converging
  EXPECT_LE(stalled.inlier_plane_rmse, cycling.inlier_plane_rmse);
}

// Where every iteration lowers the residual until a tolerance is met, the stall rule never
// fires: the same bits with it on or off.
TEST_P(IcpMethods, StallRuleChangesNothingWhereICPConverges) {
  const PointCloud target = BumpySurface(8000, 2);
  const PointCloud source =
      Transformed(SubsetWithNoise(target, 0.0, 0.0005, 3), KnownMotion().inverse());
  IcpOptions options = Options(GetParam());
  const RegistrationResult off = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  options.stall_iterations = 3;
  const RegistrationResult on = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  ASSERT_TRUE(off.converged);
  EXPECT_TRUE(on.converged);
  EXPECT_EQ(on.iterations, off.iterations);
  EXPECT_TRUE(on.T_target_source.matrix() == off.T_target_source.matrix());
}

// A noisy scan of a pipe's top on its model: nothing pins the roll about the axis or the slide
// along it, so every iteration moves the pose along them by the noise and the step tolerances are
// never met. Measured along the directions the pairs pin (weak_direction_ratio), ICP converges,
// with the scan on the outer wall.
TEST(IcpWeakDirections, APipeConvergesAlongTheDirectionsItsPairsPin) {
  const double outer = 0.05, inner = 0.045, length = 0.3;
  const PointCloud model = PipeWalls(outer, inner, length);
  const PointCloud top = PipeTopScan(outer, length);
  PointCloud scan = SubsetWithNoise(top, -1.0, 0.0005, 5);  // every point kept, with noise
  scan.normals = top.normals;
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()).matrix();
  start.translation() = Eigen::Vector3d(0.002, -0.001, 0.003);
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.max_correspondence_distance_m = {0.01, 0.005};
  options.max_normal_angle_rad = 60.0 * kDeg;
  options.rotation_tolerance_rad = 1e-4;
  options.translation_tolerance_m = 1e-5;
  options.relative_rmse_tolerance = 1e-7;  // the step tolerances decide, not a flat residual
  const RegistrationResult every_direction = AlignIcp(scan, model, start, options);
  EXPECT_FALSE(every_direction.converged);  // the trap
  options.weak_direction_ratio = 0.01;
  const RegistrationResult pinned = AlignIcp(scan, model, start, options);
  EXPECT_TRUE(pinned.converged);
  EXPECT_LT(pinned.iterations, every_direction.iterations);
  double sum = 0.0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    sum += (pinned.T_target_source * scan.Point(i)).head<2>().norm();
  }
  EXPECT_NEAR(sum / static_cast<double>(scan.size()), outer, 2e-4);
  // Where every direction is pinned nothing is left out: the same bits as without, the step
  // tolerances deciding (a flat residual would end both runs alike whatever the steps).
  const PointCloud target = BumpySurface(8000, 2);
  const PointCloud source =
      Transformed(SubsetWithNoise(target, 0.0, 0.0005, 3), KnownMotion().inverse());
  IcpOptions bumpy = Options(IcpMethod::kPointToPlane);
  bumpy.relative_rmse_tolerance = 0.0;
  const RegistrationResult off = AlignIcp(source, target, Eigen::Isometry3d::Identity(), bumpy);
  bumpy.weak_direction_ratio = 0.01;
  const RegistrationResult on = AlignIcp(source, target, Eigen::Isometry3d::Identity(), bumpy);
  EXPECT_TRUE(on.converged);
  EXPECT_EQ(on.iterations, off.iterations);
  EXPECT_TRUE(on.T_target_source.matrix() == off.T_target_source.matrix());
  // Only where it means something: point-to-plane without a prior.
  bumpy.method = IcpMethod::kPointToPoint;
  EXPECT_THROW(bumpy.Check(), Error);
}

TEST(IcpBadInput, EmptyOnePointAndNaNCloudsThrow) {
  const PointCloud good = BumpySurface(100, 13);
  PointCloud empty;
  PointCloud one;
  one.points.emplace_back(0.0f, 0.0f, 0.0f);
  PointCloud with_nan = good;
  with_nan.points[17].y() = std::numeric_limits<float>::quiet_NaN();
  const auto message = [](const PointCloud& s, const PointCloud& t,
                          const IcpOptions& options) -> std::string {
    try {
      AlignIcp(s, t, Eigen::Isometry3d::Identity(), options);
    } catch (const Error& error) {
      return error.what();
    }
    return "no error";
  };
  const IcpOptions options;
  EXPECT_NE(message(empty, good, options).find("source"), std::string::npos);
  EXPECT_NE(message(good, empty, options).find("target"), std::string::npos);
  EXPECT_NE(message(one, good, options).find("source"), std::string::npos);
  EXPECT_NE(message(good, one, options).find("target"), std::string::npos);
  EXPECT_NE(message(with_nan, good, options).find("source: point 17"), std::string::npos);
  EXPECT_NE(message(good, with_nan, options).find("target: point 17"), std::string::npos);
  PointCloud no_normals = good;
  no_normals.normals.clear();
  EXPECT_NE(message(good, no_normals, Options(IcpMethod::kPointToPlane)).find("target has no"),
            std::string::npos);
  Eigen::Isometry3d bad_init = Eigen::Isometry3d::Identity();
  bad_init(0, 3) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(AlignIcp(good, good, bad_init), Error);
  Eigen::Isometry3d mirror = Eigen::Isometry3d::Identity();
  mirror(0, 0) = -1.0;
  EXPECT_THROW(AlignIcp(good, good, mirror), Error);
}

// Early stages stopped at ten times the tolerances leave the last stage to settle the pose: it
// ends where the fully converged schedule does (within the last stage's tolerances, a few
// times over), in fewer iterations.
TEST(IcpEarlyStages, LooserEarlyStagesEndAtTheSamePoseInFewerIterations) {
  const PointCloud target = BumpySurface(8000, 2, -0.25, 0.0005);
  const Eigen::Isometry3d truth = KnownMotion();
  const PointCloud source = Transformed(BumpySurface(4000, 3, 0.0, 0.0005), truth.inverse());
  IcpOptions options = Options(IcpMethod::kPointToPlane);
  options.max_correspondence_distance_m = {0.04, 0.02, 0.01};
  options.rotation_tolerance_rad = 2e-5;
  options.translation_tolerance_m = 2.5e-4;
  options.relative_rmse_tolerance = 1e-4;
  const RegistrationResult tight = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  options.early_stage_tolerance_scale = 10.0;
  const RegistrationResult loose = AlignIcp(source, target, Eigen::Isometry3d::Identity(), options);
  ASSERT_TRUE(tight.converged);
  ASSERT_TRUE(loose.converged);
  EXPECT_LT(loose.iterations, tight.iterations);
  EXPECT_LT(RotationErrorRad(loose.T_target_source, tight.T_target_source), 1e-4);
  EXPECT_LT(TranslationErrorM(loose.T_target_source, tight.T_target_source), 1e-3);
  EXPECT_LT(RotationErrorRad(loose.T_target_source, truth), 0.1 * kDeg);
  EXPECT_LT(TranslationErrorM(loose.T_target_source, truth), 1e-3);
}

TEST(IcpOptions, CheckNamesTheField) {
  const auto field_of = [](const IcpOptions& options) -> std::string {
    try {
      options.Check();
    } catch (const Error& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(field_of(IcpOptions{}), "no error");
  IcpOptions options;
  options.max_iterations = 0;
  EXPECT_NE(field_of(options).find("max_iterations"), std::string::npos);
  options = {};
  options.max_iterations_per_stage = -1;
  EXPECT_NE(field_of(options).find("max_iterations_per_stage"), std::string::npos);
  options = {};
  options.max_correspondence_distance_m = {};
  EXPECT_NE(field_of(options).find("max_correspondence_distance_m"), std::string::npos);
  options.max_correspondence_distance_m = {0.01, 0.02};
  EXPECT_NE(field_of(options).find("max_correspondence_distance_m[1]"), std::string::npos);
  options.max_correspondence_distance_m = {0.01, -1.0};
  EXPECT_NE(field_of(options).find("max_correspondence_distance_m[1]"), std::string::npos);
  options = {};
  options.stall_iterations = -1;
  EXPECT_NE(field_of(options).find("stall_iterations"), std::string::npos);
  options = {};
  options.rotation_tolerance_rad = std::nan("");
  EXPECT_NE(field_of(options).find("rotation_tolerance_rad"), std::string::npos);
  options = {};
  options.translation_tolerance_m = -1.0;
  EXPECT_NE(field_of(options).find("translation_tolerance_m"), std::string::npos);
  options = {};
  options.relative_rmse_tolerance = -1.0;
  EXPECT_NE(field_of(options).find("relative_rmse_tolerance"), std::string::npos);
  options.relative_rmse_tolerance = 1.0;
  EXPECT_NE(field_of(options).find("relative_rmse_tolerance"), std::string::npos);
  options = {};
  options.early_stage_tolerance_scale = 0.5;
  EXPECT_NE(field_of(options).find("early_stage_tolerance_scale"), std::string::npos);
  options = {};
  options.threads = -2;
  EXPECT_NE(field_of(options).find("threads"), std::string::npos);
  const PointCloud good = BumpySurface(100, 14);
  EXPECT_THROW(AlignIcp(good, good, Eigen::Isometry3d::Identity(), options), Error);
}

}  // namespace
}  // namespace uwscan::perception
