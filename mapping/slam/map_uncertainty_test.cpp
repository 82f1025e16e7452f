#include "mapping/slam/map_uncertainty.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping::test {
namespace {

// A patch of seabed 1 m below the vehicle, 0.6 m x 0.4 m, normals up.
perception::PointCloud Seabed() {
  perception::PointCloud cloud;
  for (int i = 0; i <= 30; ++i) {
    for (int j = 0; j <= 20; ++j) {
      cloud.points.emplace_back(0.02f * static_cast<float>(i) - 0.3f,
                                0.02f * static_cast<float>(j) - 0.2f, 1.0f);
      cloud.normals.emplace_back(0.0f, 0.0f, -1.0f);
    }
  }
  return cloud;
}

TEST(ExpectedSurfaceError, DepthMovesASeabedAlongItsNormalAndHeadingDoesNot) {
  const perception::PointCloud seabed = Seabed();
  const std::vector<const perception::PointCloud*> clouds{&seabed};
  const std::vector<Eigen::Isometry3d> poses{Eigen::Isometry3d::Identity()};
  Matrix6d depth = Matrix6d::Zero();
  depth(5, 5) = 0.002 * 0.002;
  EXPECT_NEAR(ExpectedSurfaceErrorRms(clouds, poses, {depth}), 0.002, 1e-12);
  Matrix6d heading_and_slide = Matrix6d::Zero();
  heading_and_slide(2, 2) = 0.01 * 0.01;
  heading_and_slide(3, 3) = heading_and_slide(4, 4) = 0.05 * 0.05;
  EXPECT_NEAR(ExpectedSurfaceErrorRms(clouds, poses, {heading_and_slide}), 0.0, 1e-12);
}

TEST(ExpectedSurfaceError, AgreesWithPosesDrawnFromTheCovariance) {
  const perception::PointCloud seabed = Seabed();
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
  T_W_V.linear() =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
  T_W_V.translation() = Eigen::Vector3d(3.0, -2.0, 9.0);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  A.topRows<3>() *= 0.003;     // rad
  A.bottomRows<3>() *= 0.004;  // m
  const Matrix6d covariance = A * A.transpose();
  const double expected = ExpectedSurfaceErrorRms({&seabed}, {T_W_V}, {covariance});

  // Poses drawn from the covariance (the pose graph's convention: the rotation turns about the
  // position, then the position moves), each point's displacement along its true normal.
  const Eigen::LLT<Matrix6d> llt(covariance);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  double sum = 0.0;
  std::size_t count = 0;
  for (int draw = 0; draw < 3000; ++draw) {
    Eigen::Matrix<double, 6, 1> z;
    for (int k = 0; k < 6; ++k) z(k) = normal(rng);
    const Eigen::Matrix<double, 6, 1> e = llt.matrixL() * z;
    Eigen::Isometry3d moved = T_W_V;
    const Eigen::AngleAxisd turn(e.head<3>().norm(), e.head<3>().normalized());
    moved.linear() = turn.toRotationMatrix() * T_W_V.linear();
    moved.translation() += e.tail<3>();
    for (std::size_t i = 0; i < seabed.size(); i += 7) {
      const Eigen::Vector3d n_W = T_W_V.linear() * seabed.normals[i].cast<double>();
      const double d = n_W.dot(moved * seabed.Point(i) - T_W_V * seabed.Point(i));
      sum += d * d;
      ++count;
    }
  }
  const double sampled = std::sqrt(sum / static_cast<double>(count));
  EXPECT_NEAR(expected / sampled, 1.0, 0.05)
      << expected << " m predicted, " << sampled << " m sampled";
}

// The message of the uwscan::Error `call` throws ("" when it throws none).
template <typename Call>
std::string ErrorOf(Call call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ExpectedSurfaceError, MismatchedInputsGiveAClearError) {
  const perception::PointCloud seabed = Seabed();
  perception::PointCloud bare = seabed;
  bare.normals.clear();
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const auto says = [](const std::string& message, const char* what) {
    EXPECT_NE(message.find(what), std::string::npos)
        << "'" << message << "' does not say '" << what << "'";
  };
  says(ErrorOf([&] { ExpectedSurfaceErrorRms({&seabed}, {}, {Matrix6d::Identity()}); }),
       "1 clouds, 0 poses and 1 covariances");
  says(ErrorOf([&] { ExpectedSurfaceErrorRms({&bare}, {pose}, {Matrix6d::Identity()}); }),
       "submap 0 has no normals");
  says(ErrorOf([&] { ExpectedSurfaceErrorRms({&seabed}, {pose}, {Matrix6d::Identity()}, 0); }),
       "stride must be > 0");
}

TEST(ExpectedPositionError, IsTheRmsOfPositionErrorsDrawnFromTheCovariancesAndIgnoresRotation) {
  // Two poses: one uncertain in x and y, one in depth and with a large, correlated rotation
  // (a turn about the pose's own position does not move it).
  Matrix6d sideways = Matrix6d::Zero();
  sideways(3, 3) = 0.004 * 0.004;
  sideways(4, 4) = 0.002 * 0.002;
  sideways(3, 4) = sideways(4, 3) = 0.5 * 0.004 * 0.002;
  Matrix6d turned = Matrix6d::Zero();
  turned.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * 0.05 * 0.05;
  turned(5, 5) = 0.001 * 0.001;
  turned(2, 5) = turned(5, 2) = 0.5 * 0.05 * 0.001;
  const double expected = ExpectedPositionErrorRms({sideways, turned});
  EXPECT_NEAR(expected, std::sqrt((16e-6 + 4e-6 + 1e-6) / 2.0), 1e-15);

  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  double sum = 0.0;
  const int draws = 20000;
  for (const Matrix6d& covariance : {sideways, turned}) {
    const Eigen::LDLT<Matrix6d> ldlt(covariance);  // semi-definite: LDLT, not LLT
    const Matrix6d L = ldlt.transpositionsP().transpose() * Matrix6d(ldlt.matrixL()) *
                       ldlt.vectorD().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    for (int draw = 0; draw < draws; ++draw) {
      Eigen::Matrix<double, 6, 1> z;
      for (int k = 0; k < 6; ++k) z(k) = normal(rng);
      sum += (L * z).tail<3>().squaredNorm();
    }
  }
  const double sampled = std::sqrt(sum / (2.0 * draws));
  EXPECT_NEAR(expected / sampled, 1.0, 0.02)
      << expected << " m predicted, " << sampled << " m sampled";
}

TEST(ExpectedPositionError, NoCovarianceOrABrokenOneGivesAClearError) {
  const auto says = [](const std::string& message, const char* what) {
    EXPECT_NE(message.find(what), std::string::npos)
        << "'" << message << "' does not say '" << what << "'";
  };
  says(ErrorOf([] { ExpectedPositionErrorRms({}); }), "no pose covariances");
  Matrix6d broken = Matrix6d::Identity();
  broken(4, 4) = std::nan("");
  says(ErrorOf([&] {
         ExpectedPositionErrorRms({Matrix6d::Identity(), broken});
       }),
       "pose 1 has position variance");
}

}  // namespace
}  // namespace uwscan::mapping::test
