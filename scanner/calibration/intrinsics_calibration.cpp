#include "scanner/calibration/intrinsics_calibration.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "scanner/calibration/pattern_pose.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr int kMinCornersPerView = 4;

// One view in OpenCV's form (calibrateCamera takes single precision only; float keeps
// ~1e-4 px at 2000 px, far below corner noise).
struct CvView {
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
};

// Fewer than 4 corners, or all on one line, fix no homography: such a view cannot be used.
bool Usable(const CornerCorrespondences& corners) {
  if (corners.points_O.size() < kMinCornersPerView) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& p : corners.points_O) mean += p.head<2>();
  mean /= static_cast<double>(corners.points_O.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : corners.points_O) {
    const Eigen::Vector2d d = p.head<2>() - mean;
    scatter += d * d.transpose();
  }
  const Eigen::Vector2d spread =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues();
  return spread(0) > 1e-6 * spread(1);
}

struct CvCalibration {
  cv::Mat K;
  cv::Mat D;
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  cv::Mat std_intrinsics;  // fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tx ty
  cv::Mat per_view_rms;
  double rms = 0.0;
};

CvCalibration Calibrate(const std::vector<CvView>& views, const std::vector<int>& active,
                        cv::Size size, bool fix_k3) {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const int i : active) {
    object.push_back(views[static_cast<std::size_t>(i)].object);
    image.push_back(views[static_cast<std::size_t>(i)].image);
  }
  CvCalibration c;
  cv::Mat std_extrinsics;
  const int flags = fix_k3 ? cv::CALIB_FIX_K3 : 0;
  // OpenCV's default stops after 30 iterations; allow more, to the last digit.
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200,
                                  DBL_EPSILON);
  try {
    c.rms = cv::calibrateCamera(object, image, size, c.K, c.D, c.rvecs, c.tvecs, c.std_intrinsics,
                                std_extrinsics, c.per_view_rms, flags, criteria);
  } catch (const cv::Exception& e) {
    throw Error(std::string("CalibrateIntrinsics: OpenCV's calibrateCamera failed: ") + e.what());
  }
  c.K.convertTo(c.K, CV_64F);
  c.D.convertTo(c.D, CV_64F);
  c.std_intrinsics.convertTo(c.std_intrinsics, CV_64F);
  c.per_view_rms.convertTo(c.per_view_rms, CV_64F);
  return c;
}

Eigen::Isometry3d ToIsometry(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  R.convertTo(R, CV_64F);
  cv::Mat t;
  tvec.convertTo(t, CV_64F);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R.at<double>(r, c);
    T.translation()(r) = t.at<double>(r);
  }
  return T;
}

// 2-D reprojection rms of a view left out of the calibration, posed with the final intrinsics.
double RmsOfLeftOutView(const CvView& view, const cv::Mat& K, const cv::Mat& D) {
  cv::Mat rvec;
  cv::Mat tvec;
  try {
    if (!cv::solvePnP(view.object, view.image, K, D, rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
      return std::numeric_limits<double>::quiet_NaN();
    }
    cv::solvePnPRefineLM(view.object, view.image, K, D, rvec, tvec);
    std::vector<cv::Point2f> projected;
    cv::projectPoints(view.object, rvec, tvec, K, D, projected);
    double sum_sq = 0.0;
    for (std::size_t j = 0; j < projected.size(); ++j) {
      const cv::Point2f d = projected[j] - view.image[j];
      sum_sq += static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y;
    }
    return std::sqrt(sum_sq / static_cast<double>(projected.size()));
  } catch (const cv::Exception&) {
    return std::numeric_limits<double>::quiet_NaN();  // a view PnP cannot pose at all
  }
}

// Every view in OpenCV's form, and which of them can be used.
struct CvViews {
  std::vector<CvView> views;  // in view order
  std::vector<int> usable;    // indices into views, ascending
  int unusable = 0;
};

CvViews ToCvViews(const PatternSpec& spec, const std::vector<PatternObservation>& observations) {
  const int m = static_cast<int>(observations.size());
  CvViews cv_views;
  cv_views.views.resize(observations.size());
  for (int i = 0; i < m; ++i) {
    const CornerCorrespondences corners =
        MatchCorners(spec, observations[static_cast<std::size_t>(i)], i);
    CvView& view = cv_views.views[static_cast<std::size_t>(i)];
    for (std::size_t j = 0; j < corners.points_O.size(); ++j) {
      const Eigen::Vector3d& p = corners.points_O[j];
      view.object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                               static_cast<float>(p.z()));
      view.image.emplace_back(static_cast<float>(corners.pixels[j].x()),
                              static_cast<float>(corners.pixels[j].y()));
    }
    if (Usable(corners)) {
      cv_views.usable.push_back(i);
    } else {
      ++cv_views.unusable;
    }
  }
  return cv_views;
}

// The final calibration and the views it was made from.
struct Selection {
  CvCalibration calibration;
  std::vector<int> active;     // views calibrated from, ascending
  std::vector<bool> rejected;  // per view: rejected for its rms (not merely unusable)
};

// Index into `active` of the view with the largest rms (the first such).
int WorstView(const CvCalibration& calibration, int active) {
  int worst = 0;
  for (int k = 1; k < active; ++k) {
    if (calibration.per_view_rms.at<double>(k) > calibration.per_view_rms.at<double>(worst)) {
      worst = k;
    }
  }
  return worst;
}

// Calibrates from the usable views, then drops the worst view while its rms is above the limit
// and calibrates again (see the header). Throws when fewer than min_views remain.
Selection CalibrateRejectingWorst(const CvViews& views, cv::Size size,
                                  const IntrinsicsOptions& options) {
  Selection fit;
  fit.active = views.usable;
  fit.rejected.assign(views.views.size(), false);
  int rejected_count = 0;
  for (;;) {
    if (static_cast<int>(fit.active.size()) < options.min_views) {
      std::ostringstream message;
      message << "CalibrateIntrinsics: " << fit.active.size() << " of " << views.views.size()
              << " views usable, need " << options.min_views << " (" << views.unusable
              << " with fewer than " << kMinCornersPerView << " corners or all on one line, "
              << rejected_count << " rejected with an rms above " << options.reject_view_rms_px
              << " px)";
      throw Error(message.str());
    }
    fit.calibration = Calibrate(views.views, fit.active, size, options.fix_k3);
    const int worst = WorstView(fit.calibration, static_cast<int>(fit.active.size()));
    if (!(fit.calibration.per_view_rms.at<double>(worst) > options.reject_view_rms_px)) break;
    fit.rejected[static_cast<std::size_t>(fit.active[static_cast<std::size_t>(worst)])] = true;
    ++rejected_count;
    fit.active.erase(fit.active.begin() + worst);
  }
  return fit;
}

// The camera OpenCV's K and distortion describe; throws when it is not usable.
PinholeCamera CameraOf(const CvCalibration& calibration, int width_px, int height_px) {
  const cv::Mat& K = calibration.K;
  const cv::Mat& D = calibration.D;
  PinholeCamera camera;
  camera.width_px = width_px;
  camera.height_px = height_px;
  camera.fx_px = K.at<double>(0, 0);
  camera.fy_px = K.at<double>(1, 1);
  camera.cx_px = K.at<double>(0, 2);
  camera.cy_px = K.at<double>(1, 2);
  const auto coefficient = [&D](int k) {
    return k < static_cast<int>(D.total()) ? D.at<double>(k) : 0.0;
  };
  camera.k1 = coefficient(0);
  camera.k2 = coefficient(1);
  camera.p1 = coefficient(2);
  camera.p2 = coefficient(3);
  camera.k3 = coefficient(4);
  try {
    camera.Check();
  } catch (const Error& e) {
    throw Error(std::string("CalibrateIntrinsics: the calibration is not usable: ") + e.what());
  }
  return camera;
}

// Every view's residual: the calibration's own for the views it used, a PnP pose's with the
// final intrinsics for the rejected ones, NaN for the unusable ones.
std::vector<ViewResidual> ViewResiduals(const std::vector<PatternObservation>& observations,
                                        const std::vector<CvView>& views, const Selection& fit) {
  std::vector<ViewResidual> residuals(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i) {
    ViewResidual& view = residuals[i];
    view.image = observations[i].image;
    view.rejected = true;
    view.rms_px = std::numeric_limits<double>::quiet_NaN();
    if (fit.rejected[i])
      view.rms_px = RmsOfLeftOutView(views[i], fit.calibration.K, fit.calibration.D);
  }
  for (std::size_t k = 0; k < fit.active.size(); ++k) {
    ViewResidual& view = residuals[static_cast<std::size_t>(fit.active[k])];
    view.rejected = false;
    view.rms_px = fit.calibration.per_view_rms.at<double>(static_cast<int>(k));
  }
  return residuals;
}

// Every view's pattern pose from the calibration; identity for the views it did not use.
std::vector<Eigen::Isometry3d> ViewPoses(std::size_t view_count, const Selection& fit) {
  std::vector<Eigen::Isometry3d> T_C_O(view_count, Eigen::Isometry3d::Identity());
  for (std::size_t k = 0; k < fit.active.size(); ++k) {
    T_C_O[static_cast<std::size_t>(fit.active[k])] =
        ToIsometry(fit.calibration.rvecs[k], fit.calibration.tvecs[k]);
  }
  return T_C_O;
}

}  // namespace

void IntrinsicsOptions::Check() const {
  const OptionChecks check("IntrinsicsOptions");
  check.AtLeast("min_views", min_views, 3,
                "(Zhang's method needs three views of a plane to fix every intrinsic)");
  check.Positive("reject_view_rms_px", reject_view_rms_px, "px");
}

IntrinsicsResult CalibrateIntrinsics(const PatternSpec& spec,
                                     const std::vector<PatternObservation>& observations,
                                     int width_px, int height_px,
                                     const IntrinsicsOptions& options) {
  options.Check();
  spec.Check();
  if (width_px <= 0 || height_px <= 0) {
    throw Error("CalibrateIntrinsics: image size must be positive, got " +
                std::to_string(width_px) + " x " + std::to_string(height_px) + " px");
  }
  const CvViews views = ToCvViews(spec, observations);
  const Selection fit = CalibrateRejectingWorst(views, cv::Size(width_px, height_px), options);

  IntrinsicsResult result;
  result.camera = CameraOf(fit.calibration, width_px, height_px);
  const cv::Mat& s = fit.calibration.std_intrinsics;
  result.fx_std = s.at<double>(0);
  result.fy_std = s.at<double>(1);
  result.cx_std = s.at<double>(2);
  result.cy_std = s.at<double>(3);
  for (int k = 0; k < 5; ++k)
    result.distortion_std[static_cast<std::size_t>(k)] = s.at<double>(4 + k);
  result.rms_px = fit.calibration.rms;
  result.views = ViewResiduals(observations, views.views, fit);
  result.T_C_O = ViewPoses(observations.size(), fit);
  return result;
}

}  // namespace uwscan::scanner::calibration
