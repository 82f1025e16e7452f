#include "mapping/slam/relative_pose_cost.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <random>
#include <vector>

namespace uwscan::mapping::test {
namespace {

// The reference: the same error written for Ceres's automatic differentiation.
template <typename T>
Eigen::Matrix<T, 6, 1> ReferenceError(const T* q_a_raw, const T* p_a_raw, const T* q_b_raw,
                                      const T* p_b_raw, const Eigen::Quaterniond& q_meas,
                                      const Eigen::Matrix<T, 3, 1>& t_meas) {
  const Eigen::Map<const Eigen::Quaternion<T>> q_a(q_a_raw), q_b(q_b_raw);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(p_a_raw), p_b(p_b_raw);
  Eigen::Quaternion<T> q_d = (q_a.conjugate() * q_b) * q_meas.conjugate().cast<T>();
  if (q_d.w() < T(0)) q_d.coeffs() = -q_d.coeffs();
  Eigen::Matrix<T, 6, 1> e;
  e << T(2) * q_d.vec(), q_a.conjugate() * (p_b - p_a) - q_d * t_meas;
  return e;
}

struct ReferenceRelative {
  RelativePoseMeasurement m;
  template <typename T>
  bool operator()(const T* q_a, const T* p_a, const T* q_b, const T* p_b, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out(residual);
    out = m.sqrt_information.cast<T>() *
          ReferenceError<T>(q_a, p_a, q_b, p_b, m.q_meas, m.t_meas.cast<T>());
    return true;
  }
};

struct ReferenceDeadReckoned {
  RelativePoseMeasurement m;
  template <typename T>
  bool operator()(const T* q_a, const T* p_a, const T* q_b, const T* p_b, const T* c,
                  T* residual) const {
    const Eigen::Matrix<T, 3, 1> t_true =
        DeadReckoningCalibration::Correct<T>(m.t_meas.cast<T>(), c[0], c[1]);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out(residual);
    out = m.sqrt_information.cast<T>() * ReferenceError<T>(q_a, p_a, q_b, p_b, m.q_meas, t_true);
    return true;
  }
};

Eigen::Quaterniond RandomRotation(std::mt19937& random) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random))
      .normalized();
}

Eigen::Vector3d RandomVector(std::mt19937& random, double scale) {
  std::normal_distribution<double> normal(0.0, scale);
  return {normal(random), normal(random), normal(random)};
}

// An edge's parameter blocks: two nodes and a calibration.
struct Blocks {
  std::array<double, 4> q_a, q_b;
  std::array<double, 3> p_a, p_b;
  std::array<double, 2> calibration;
  std::vector<double*> pointers() {
    return {q_a.data(), p_a.data(), q_b.data(), p_b.data(), calibration.data()};
  }
};

// Evaluates `cost` with every Jacobian; the quaternions' ones times the manifold's Plus Jacobian
// (what the solver uses), the others as they are.
struct Evaluation {
  Eigen::Matrix<double, 6, 1> residual;
  std::vector<Eigen::MatrixXd> jacobians;
};

Evaluation Evaluate(const ceres::CostFunction& cost, Blocks& blocks) {
  const std::vector<int>& sizes = cost.parameter_block_sizes();
  std::vector<double*> parameters = blocks.pointers();
  std::vector<std::vector<double>> storage;
  std::vector<double*> jacobians;
  for (const int size : sizes) {
    storage.emplace_back(static_cast<std::size_t>(6 * size));
    jacobians.push_back(storage.back().data());
  }
  Evaluation out;
  EXPECT_TRUE(cost.Evaluate(parameters.data(), out.residual.data(), jacobians.data()));
  const ceres::EigenQuaternionManifold manifold;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const Eigen::MatrixXd ambient =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[i], 6, sizes[i]);
    if (sizes[i] != 4) {
      out.jacobians.push_back(ambient);
      continue;
    }
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
    EXPECT_TRUE(manifold.PlusJacobian(parameters[i], plus.data()));
    out.jacobians.push_back(ambient * plus);
  }
  return out;
}

void ExpectSame(const Evaluation& analytic, const Evaluation& reference) {
  const double scale = 1.0 + reference.residual.norm();
  EXPECT_LT((analytic.residual - reference.residual).norm(), 1e-12 * scale);
  ASSERT_EQ(analytic.jacobians.size(), reference.jacobians.size());
  for (std::size_t i = 0; i < analytic.jacobians.size(); ++i) {
    const double size = 1.0 + reference.jacobians[i].norm();
    EXPECT_LT((analytic.jacobians[i] - reference.jacobians[i]).norm(), 1e-10 * size)
        << "block " << i << "\nanalytic\n"
        << analytic.jacobians[i] << "\nreference\n"
        << reference.jacobians[i];
  }
}

TEST(RelativePoseCost, MatchesAutomaticDifferentiationAlongTheManifoldOnEitherSideOfTheShortWay) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> small(-0.05, 0.05);
  int flipped = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Blocks blocks;
    Eigen::Map<Eigen::Quaterniond>(blocks.q_a.data()) = RandomRotation(random);
    Eigen::Map<Eigen::Quaterniond>(blocks.q_b.data()) = RandomRotation(random);
    Eigen::Map<Eigen::Vector3d>(blocks.p_a.data()) = RandomVector(random, 20.0);
    Eigen::Map<Eigen::Vector3d>(blocks.p_b.data()) = RandomVector(random, 20.0);
    blocks.calibration = {small(random), small(random)};
    const Eigen::Matrix<double, 6, 6> root = Eigen::Matrix<double, 6, 6>::Random();
    const RelativePoseMeasurement m{RandomRotation(random), RandomVector(random, 2.0),
                                    root * root.transpose() * 10.0};
    const Eigen::Quaterniond q_d = Eigen::Map<Eigen::Quaterniond>(blocks.q_a.data()).conjugate() *
                                   Eigen::Map<Eigen::Quaterniond>(blocks.q_b.data()) *
                                   m.q_meas.conjugate();
    flipped += q_d.w() < 0.0 ? 1 : 0;
    ExpectSame(Evaluate(RelativePoseCost(m), blocks),
               Evaluate(ceres::AutoDiffCostFunction<ReferenceRelative, 6, 4, 3, 4, 3>(
                            new ReferenceRelative{m}),
                        blocks));
    ExpectSame(Evaluate(DeadReckonedPoseCost(m), blocks),
               Evaluate(ceres::AutoDiffCostFunction<ReferenceDeadReckoned, 6, 4, 3, 4, 3, 2>(
                            new ReferenceDeadReckoned{m}),
                        blocks));
  }
  // Both branches of the short way were taken.
  EXPECT_GT(flipped, 20);
  EXPECT_LT(flipped, 180);
}

TEST(RelativePoseCost, ResidualWithoutJacobiansIsTheSame) {
  std::mt19937 random(8);
  Blocks blocks;
  Eigen::Map<Eigen::Quaterniond>(blocks.q_a.data()) = RandomRotation(random);
  Eigen::Map<Eigen::Quaterniond>(blocks.q_b.data()) = RandomRotation(random);
  Eigen::Map<Eigen::Vector3d>(blocks.p_a.data()) = RandomVector(random, 1.0);
  Eigen::Map<Eigen::Vector3d>(blocks.p_b.data()) = RandomVector(random, 1.0);
  blocks.calibration = {0.01, -0.02};
  const RelativePoseMeasurement m{RandomRotation(random), RandomVector(random, 1.0),
                                  Eigen::Matrix<double, 6, 6>::Identity()};
  const DeadReckonedPoseCost cost(m);
  std::vector<double*> parameters = blocks.pointers();
  Eigen::Matrix<double, 6, 1> without, with;
  ASSERT_TRUE(cost.Evaluate(parameters.data(), without.data(), nullptr));
  const Evaluation full = Evaluate(cost, blocks);
  with = full.residual;
  EXPECT_EQ(without, with);
}

}  // namespace
}  // namespace uwscan::mapping::test
