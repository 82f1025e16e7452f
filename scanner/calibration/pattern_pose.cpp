#include "scanner/calibration/pattern_pose.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {
namespace {

// A pose as Ceres optimises it: angle-axis rotation (OpenCV's rvec) then translation, metres.
using Pose6 = std::array<double, 6>;

std::string Describe(const PatternObservation& observation, int index) {
  std::ostringstream where;
  where << "pattern observation";
  if (index >= 0) where << ' ' << index;
  if (!observation.image.empty()) where << " ('" << observation.image << "')";
  return where.str();
}

Eigen::Isometry3d ToIsometry(const Pose6& pose) {
  const Eigen::Vector3d rotation(pose[0], pose[1], pose[2]);
  const double angle = rotation.norm();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return T;
}

// Refractive reprojection residual of one corner over the pose, the viewport held fixed.
struct CornerResidual {
  CornerResidual(const RefractiveCamera& camera, const Eigen::Vector3d& p_O,
                 const Eigen::Vector2d& uv_px)
      : camera(camera), p_O(p_O), uv_px(uv_px) {}

  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const T p_O_T[3] = {T(p_O.x()), T(p_O.y()), T(p_O.z())};
    T p_C[3];
    ceres::AngleAxisRotatePoint(pose, p_O_T, p_C);
    for (int i = 0; i < 3; ++i) p_C[i] += pose[3 + i];
    const FlatViewport& v = camera.viewport;
    const T normal[3] = {T(v.normal.x()), T(v.normal.y()), T(v.normal.z())};
    T uv[2];
    if (!ProjectThroughViewport(camera.camera, normal, T(v.distance_m), T(v.thickness_m), v.n_air,
                                T(v.n_glass), T(v.n_water), p_C, uv)) {
      return false;
    }
    residual[0] = uv[0] - uv_px.x();
    residual[1] = uv[1] - uv_px.y();
    return true;
  }

  RefractiveCamera camera;
  Eigen::Vector3d p_O;
  Eigen::Vector2d uv_px;
};

// Sum of squared reprojection errors (pixels^2); infinity when a corner cannot be projected.
double Cost(const RefractiveCamera& camera, const CornerCorrespondences& corners,
            const Pose6& pose) {
  double cost = 0.0;
  for (std::size_t i = 0; i < corners.points_O.size(); ++i) {
    const CornerResidual residual(camera, corners.points_O[i], corners.pixels[i]);
    double r[2];
    if (!residual(pose.data(), r)) return std::numeric_limits<double>::infinity();
    cost += r[0] * r[0] + r[1] * r[1];
  }
  return cost;
}

// Points on one line (or one point) fix no pose. Judged on the spread of the points in the
// pattern plane: the smaller principal spread against the larger.
void RequireNotCollinear(const std::vector<Eigen::Vector3d>& points_O, const std::string& where) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& p : points_O) mean += p.head<2>();
  mean /= static_cast<double>(points_O.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : points_O) {
    const Eigen::Vector2d d = p.head<2>() - mean;
    scatter += d * d.transpose();
  }
  const Eigen::Vector2d spread =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues();
  if (!(spread(0) > 1e-6 * spread(1))) {
    throw Error(where + ": the corners lie on one line; they fix no pose");
  }
}

// The first-order effect of a flat port: near the axis a point at depth Z (along the normal)
// seen through air gap d, glass t and water is imaged as a pinhole would image it at the
// apparent depth Z_app = d + t k_glass + (Z - d - t) k_water, k = n_air / n. Pinhole PnP finds
// Z_app; this moves the pattern's centroid along its line of sight to the Z it implies.
std::optional<Pose6> CorrectedForRefraction(const FlatViewport& v,
                                            const CornerCorrespondences& corners,
                                            const Pose6& pinhole) {
  Eigen::Vector3d centroid_O = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : corners.points_O) centroid_O += p;
  centroid_O /= static_cast<double>(corners.points_O.size());
  const Eigen::Isometry3d T = ToIsometry(pinhole);
  const Eigen::Vector3d centroid_C = T * centroid_O;
  const double k_glass = v.n_air / v.n_glass;
  const double k_water = v.n_air / v.n_water;
  const double apparent = v.normal.dot(centroid_C);
  const double in_water = apparent - v.distance_m - v.thickness_m * k_glass;
  if (!(in_water > 0.0)) return std::nullopt;
  const double depth = v.distance_m + v.thickness_m + in_water / k_water;
  const Eigen::Vector3d translation = (depth / apparent) * centroid_C - T.linear() * centroid_O;
  Pose6 corrected = pinhole;
  for (int i = 0; i < 3; ++i) corrected[3 + i] = translation(i);
  return corrected;
}

struct Refined {
  Pose6 pose{};
  double cost = std::numeric_limits<double>::infinity();
  int iterations = 0;
  bool converged = false;
};

Refined Refine(const RefractiveCamera& camera, const CornerCorrespondences& corners,
               const Pose6& start) {
  Refined refined;
  refined.pose = start;
  ceres::Problem problem;
  for (std::size_t i = 0; i < corners.points_O.size(); ++i) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<CornerResidual, 2, 6>(
            new CornerResidual(camera, corners.points_O[i], corners.pixels[i])),
        nullptr, refined.pose.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  // Exact corners must give the exact pose: stop on the step size, not on a loose cost or
  // gradient test (the cost of exact data keeps falling by orders of magnitude to ~1e-25).
  options.function_tolerance = 1e-15;
  options.gradient_tolerance = 0.0;
  options.parameter_tolerance = 1e-14;
  options.num_threads = 1;  // deterministic
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  refined.cost = 2.0 * summary.final_cost;
  if (!std::isfinite(refined.cost) || summary.termination_type == ceres::FAILURE) {
    refined.cost = std::numeric_limits<double>::infinity();
  }
  refined.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  refined.converged = summary.termination_type == ceres::CONVERGENCE;
  return refined;
}

}  // namespace

CornerCorrespondences MatchCorners(const PatternSpec& spec, const PatternObservation& observation,
                                   int index_for_messages) {
  spec.Check();
  const std::string where = Describe(observation, index_for_messages);
  if (observation.corner_ids.size() != observation.corners_px.size()) {
    throw Error(where + ": " + std::to_string(observation.corner_ids.size()) + " corner ids but " +
                std::to_string(observation.corners_px.size()) + " corners");
  }
  const std::vector<Eigen::Vector3d> points_O = spec.CornerPoints_O();
  std::vector<bool> seen(points_O.size(), false);
  CornerCorrespondences corners;
  corners.points_O.reserve(observation.corner_ids.size());
  corners.pixels.reserve(observation.corner_ids.size());
  for (std::size_t i = 0; i < observation.corner_ids.size(); ++i) {
    const int id = observation.corner_ids[i];
    if (id < 0 || id >= static_cast<int>(points_O.size())) {
      throw Error(where + ": corner " + std::to_string(i) + " has id " + std::to_string(id) +
                  ", expected 0.." + std::to_string(points_O.size() - 1) + " for this pattern");
    }
    if (seen[static_cast<std::size_t>(id)]) {
      throw Error(where + ": corner id " + std::to_string(id) + " appears twice");
    }
    seen[static_cast<std::size_t>(id)] = true;
    const Eigen::Vector2d& uv = observation.corners_px[i];
    if (!uv.allFinite()) {
      throw Error(where + ": corner " + std::to_string(i) + " (id " + std::to_string(id) +
                  ") is not finite");
    }
    corners.points_O.push_back(points_O[static_cast<std::size_t>(id)]);
    corners.pixels.push_back(uv);
  }
  return corners;
}

PatternPose EstimatePatternPose(const RefractiveCamera& camera, const PatternSpec& spec,
                                const PatternObservation& observation) {
  camera.Check();
  const std::string where = "EstimatePatternPose: " + Describe(observation, -1);
  const CornerCorrespondences corners = MatchCorners(spec, observation);
  if (corners.points_O.size() < 4) {
    throw Error(where + ": " + std::to_string(corners.points_O.size()) +
                " corners, need at least 4 for a pose");
  }
  RequireNotCollinear(corners.points_O, where);

  // Planar PnP in normalised coordinates (identity camera matrix, no distortion).
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> normalised;
  for (std::size_t i = 0; i < corners.points_O.size(); ++i) {
    const std::optional<Eigen::Vector2d> xy = camera.camera.Undistort(corners.pixels[i]);
    if (!xy) {
      std::ostringstream message;
      message << where << ": corner " << i << " at (" << corners.pixels[i].x() << ", "
              << corners.pixels[i].y() << ") px cannot be undistorted (beyond the fold of the "
              << "distortion model)";
      throw Error(message.str());
    }
    const Eigen::Vector3d& p = corners.points_O[i];
    object.emplace_back(p.x(), p.y(), p.z());
    normalised.emplace_back(xy->x(), xy->y());
  }
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  try {
    cv::solvePnPGeneric(object, normalised, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvecs, tvecs,
                        false, cv::SOLVEPNP_IPPE);
  } catch (const cv::Exception& e) {
    throw Error(where + ": planar PnP failed: " + e.what());
  }

  // IPPE returns both poses of the planar ambiguity; each also enters refraction-corrected.
  std::vector<Pose6> starts;
  for (std::size_t k = 0; k < rvecs.size(); ++k) {
    cv::Mat r;
    cv::Mat t;
    rvecs[k].convertTo(r, CV_64F);
    tvecs[k].convertTo(t, CV_64F);
    const Pose6 pinhole = {r.at<double>(0), r.at<double>(1), r.at<double>(2),
                           t.at<double>(0), t.at<double>(1), t.at<double>(2)};
    if (!std::all_of(pinhole.begin(), pinhole.end(), [](double x) { return std::isfinite(x); })) {
      continue;
    }
    starts.push_back(pinhole);
    if (const std::optional<Pose6> corrected =
            CorrectedForRefraction(camera.viewport, corners, pinhole)) {
      starts.push_back(*corrected);
    }
  }

  Refined best;
  for (const Pose6& start : starts) {
    if (!std::isfinite(Cost(camera, corners, start))) continue;  // a corner behind the port
    const Refined refined = Refine(camera, corners, start);
    if (refined.cost < best.cost) best = refined;
  }
  if (!std::isfinite(best.cost)) {
    throw Error(where + ": no pose puts every corner beyond the viewport's outer face");
  }
  PatternPose pose;
  pose.T_C_O = ToIsometry(best.pose);
  pose.rms_px = std::sqrt(best.cost / static_cast<double>(corners.points_O.size()));
  pose.iterations = best.iterations;
  pose.converged = best.converged;
  return pose;
}

}  // namespace uwscan::scanner::calibration
