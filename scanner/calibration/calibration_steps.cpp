#include "scanner/calibration/calibration_steps.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "scanner/calibration/dot_detection.hpp"
#include "scanner/calibration/galvo_laser_calibration.hpp"
#include "scanner/calibration/intrinsics_calibration.hpp"
#include "scanner/calibration/laser_points.hpp"
#include "scanner/calibration/laser_viewport_calibration.hpp"
#include "scanner/calibration/mems_calibration.hpp"
#include "scanner/calibration/parameter_lists.hpp"
#include "scanner/calibration/pattern_detection.hpp"
#include "scanner/calibration/pattern_pose.hpp"
#include "scanner/calibration/stripe_extraction.hpp"
#include "scanner/calibration/viewport_calibration.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {
namespace {

using Clock = std::chrono::steady_clock;

std::string Format(const char* format, double a, double b = 0.0, double c = 0.0) {
  char text[256];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

// A viewport estimated in the dataset's medium, written back with the refractive indices of the
// file it goes into (the medium it is meant for), except those the step estimated.
FlatViewport KeepIndices(FlatViewport estimated, const FlatViewport& file, bool water_estimated,
                         bool glass_estimated) {
  estimated.n_air = file.n_air;
  if (!water_estimated) estimated.n_water = file.n_water;
  if (!glass_estimated) estimated.n_glass = file.n_glass;
  return estimated;
}

// The board plane of a pose: z_O = 0 in the camera frame, offset >= 0.
Plane BoardPlane(const Eigen::Isometry3d& T_C_O) {
  Plane plane;
  plane.normal = T_C_O.linear().col(2);
  plane.offset_m = plane.normal.dot(T_C_O.translation());
  if (plane.offset_m < 0.0) {
    plane.normal = -plane.normal;
    plane.offset_m = -plane.offset_m;
  }
  return plane;
}

void AddViewportParams(const std::string& key, const FlatViewport& v, double normal_std,
                       double distance_std, double thickness_std, StepRecord* record) {
  for (const ParameterEstimate& p :
       ViewportParameters(key, v, ViewportStds{normal_std, distance_std, thickness_std})) {
    record->params.push_back(p);
  }
}

class StepRunner {
 public:
  StepRunner(const CalibrationDataset& dataset, const std::function<void(double)>& progress)
      : dataset_(dataset), progress_(progress) {}

  // Pattern observations of the dataset's views; views without a pattern are reported.
  std::vector<PatternObservation> ViewObservations(std::vector<std::string>* missing) const {
    std::vector<PatternObservation> observations;
    for (size_t i = 0; i < dataset_.views.size(); ++i) {
      std::optional<PatternObservation> found =
          DetectPattern(dataset_.ImagePath(dataset_.views[i]), dataset_.pattern);
      if (found) {
        found->image = dataset_.views[i];
        observations.push_back(*found);
      } else {
        missing->push_back(dataset_.views[i]);
      }
      Report(static_cast<double>(i + 1) / dataset_.views.size());
    }
    if (observations.empty()) {
      throw Error(dataset_.folder.string() + ": no calibration pattern found in any of its " +
                  std::to_string(dataset_.views.size()) + " views");
    }
    return observations;
  }

  // Each plane's pose (PnP through the known camera) and what was projected on it.
  struct PlaneData {
    std::vector<Plane> planes;
    std::vector<std::vector<StripeObservation>> stripes;
    std::vector<std::vector<DotObservation>> dots;
    int pose_corners = 0;
    double pose_rms_px = 0.0;
  };
  PlaneData Planes(const RefractiveCamera& camera) const {
    PlaneData data;
    const size_t total = dataset_.planes.size();
    double sum2 = 0.0;
    StripeDetectorOptions detector;
    detector.axis = StripeAxis::kRows;
    for (size_t l = 0; l < total; ++l) {
      const CalibrationDataset::Plane& plane = dataset_.planes[l];
      const std::optional<PatternObservation> board =
          DetectPattern(dataset_.ImagePath(plane.pattern_image), dataset_.pattern);
      if (!board) {
        throw Error(dataset_.ImagePath(plane.pattern_image).string() +
                    ": no calibration pattern found: the plane's pose is unknown");
      }
      const PatternPose pose = EstimatePatternPose(camera, dataset_.pattern, *board);
      data.planes.push_back(BoardPlane(pose.T_C_O));
      data.pose_corners += static_cast<int>(board->corners_px.size());
      sum2 += pose.rms_px * pose.rms_px * board->corners_px.size();
      data.stripes.emplace_back();
      for (const auto& [image, step] : plane.stripes) {
        StripeObservation s = ExtractStripe(dataset_.ImagePath(image), step, detector);
        s.image = image;
        data.stripes.back().push_back(std::move(s));
      }
      data.dots.emplace_back();
      for (const auto& [image, volts] : plane.dots) {
        const std::optional<Eigen::Vector2d> dot = DetectDot(dataset_.ImagePath(image));
        if (!dot) continue;  // a dot the camera did not catch: that pair has one plane fewer
        data.dots.back().push_back(DotObservation{image, volts, *dot});
      }
      Report(static_cast<double>(l + 1) / total);
    }
    data.pose_rms_px = data.pose_corners > 0 ? std::sqrt(sum2 / data.pose_corners) : 0.0;
    return data;
  }

  void Report(double fraction) const {
    if (progress_) progress_(std::clamp(fraction, 0.0, 1.0));
  }

 private:
  const CalibrationDataset& dataset_;
  const std::function<void(double)>& progress_;
};

CalibrationStepOutcome Intrinsics(const CalibrationDataset& d, const Scanner& initial,
                                  const StepRunner& run) {
  std::vector<std::string> missing;
  const std::vector<PatternObservation> views = run.ViewObservations(&missing);
  const IntrinsicsResult r =
      CalibrateIntrinsics(d.pattern, views, d.width_px, d.height_px, IntrinsicsOptions{});
  CalibrationStepOutcome out;
  out.scanner = initial;
  out.scanner.camera().camera = r.camera;
  StepRecord& rec = out.record;
  rec.residual_unit = "px";
  rec.residual_rms = r.rms_px;
  int rejected = 0;
  for (const ViewResidual& v : r.views) {
    rec.residual_max = std::max(rec.residual_max, v.rms_px);
    rejected += v.rejected ? 1 : 0;
  }
  for (const PatternObservation& v : views)
    rec.observations += static_cast<int>(v.corners_px.size());
  const PinholeCamera& c = r.camera;
  rec.params = CameraParameters(c, &r);
  out.summary.push_back(Format("%.0f views with the pattern, %.0f without, %.0f rejected",
                               views.size(), missing.size(), rejected));
  out.summary.push_back(
      Format("reprojection rms %.3f px; fx %.2f px, fy %.2f px", r.rms_px, c.fx_px, c.fy_px));
  return out;
}

CalibrationStepOutcome Viewport(const CalibrationDataset& d, const Scanner& work,
                                const Scanner& initial, const StepRunner& run,
                                const CalibrationStepOptions& options) {
  const RefractiveCamera& camera = work.camera();
  std::vector<std::string> missing;
  const std::vector<PatternObservation> views = run.ViewObservations(&missing);
  ViewportCalibrationOptions viewport_options;
  viewport_options.refine_thickness = options.refine_thickness;
  viewport_options.refine_water_index = options.refine_water_index;
  viewport_options.refine_glass_index = options.refine_glass_index;
  const ViewportCalibrationResult r =
      CalibrateCameraViewport(camera.camera, camera.viewport, d.pattern, views, viewport_options);
  CalibrationStepOutcome out;
  out.scanner = initial;
  out.scanner.camera().viewport =
      KeepIndices(r.viewport, initial.camera().viewport, options.refine_water_index,
                  options.refine_glass_index);
  StepRecord& rec = out.record;
  rec.residual_unit = "px";
  rec.residual_rms = r.rms_px;
  rec.residual_max = r.max_px;
  for (const PatternObservation& v : views)
    rec.observations += static_cast<int>(v.corners_px.size());
  AddViewportParams("camera_viewport", r.viewport, r.normal_std_rad, r.distance_std_m,
                    r.thickness_std_m, &rec);
  if (options.refine_water_index)
    rec.params.push_back({"camera_viewport.n_water", r.viewport.n_water, r.n_water_std});
  if (options.refine_glass_index)
    rec.params.push_back({"camera_viewport.n_glass", r.viewport.n_glass, r.n_glass_std});
  out.summary.push_back(Format("%.0f views with the pattern, %.0f without; %.0f iterations",
                               views.size(), missing.size(), r.iterations));
  out.summary.push_back(
      Format("refractive reprojection rms %.3f px; viewport distance %.2f mm, thickness %.2f mm",
             r.rms_px, r.viewport.distance_m * 1e3, r.viewport.thickness_m * 1e3));
  return out;
}

CalibrationStepOutcome Laser(const Scanner& work, const Scanner& initial, const std::string& source,
                             const StepRunner& run, bool laser_viewport,
                             const CalibrationStepOptions& options) {
  if (work.kind() == ScannerKind::kMems) {
    throw Error(source + ": the laser steps calibrate a galvanometer scanner; this one is MEMS");
  }
  const GalvoScannerModel& model = work.galvo();
  const StepRunner::PlaneData planes = run.Planes(model.camera);
  const std::vector<LaserCalibrationPoint> points =
      LaserCalibrationPoints(model.camera, planes.planes, planes.stripes);
  CalibrationStepOutcome out;
  out.scanner = initial;
  StepRecord& rec = out.record;
  rec.residual_unit = "m";
  rec.observations = static_cast<int>(points.size());
  if (!laser_viewport) {
    const GalvoLaserCalibrationResult r =
        CalibrateGalvoLaser(points, model.laser, GalvoLaserCalibrationOptions{});
    GalvoLaser& laser = out.scanner.galvo().laser;
    laser.T_C_L = r.laser.T_C_L;
    laser.T_C_M = r.laser.T_C_M;
    laser.mirror_step_rad = r.laser.mirror_step_rad;
    laser.rotation_distance_m = r.laser.rotation_distance_m;
    rec.residual_rms = r.residual_rms_m;
    rec.residual_max = r.residual_max_m;
    rec.params = GalvoLaserParameters(r.laser, &r.std_devs);
    out.summary.push_back(Format("%.0f calibration points on %.0f planes (board poses %.3f px rms)",
                                 points.size(), planes.planes.size(), planes.pose_rms_px));
    out.summary.push_back(
        Format("laser fan residual rms %.4f mm, max %.4f mm; mirror step %.6f rad",
               r.residual_rms_m * 1e3, r.residual_max_m * 1e3, r.laser.mirror_step_rad));
  } else {
    LaserViewportCalibrationOptions viewport_options;
    viewport_options.refine_thickness = options.refine_thickness;
    const LaserViewportCalibrationResult r =
        CalibrateLaserViewport(model, points, viewport_options);
    out.scanner.laser_viewport() = KeepIndices(r.viewport, initial.laser_viewport(), false, false);
    rec.residual_rms = r.residual_rms_m;
    rec.residual_max = r.residual_max_m;
    AddViewportParams("laser_viewport", r.viewport, r.normal_std_rad, r.distance_std_m,
                      r.thickness_std_m, &rec);
    out.summary.push_back(Format("%.0f calibration points on %.0f planes (board poses %.3f px rms)",
                                 points.size(), planes.planes.size(), planes.pose_rms_px));
    out.summary.push_back(Format("ray-ray residual rms %.4f mm, max %.4f mm",
                                 r.residual_rms_m * 1e3, r.residual_max_m * 1e3));
  }
  return out;
}

CalibrationStepOutcome Mems(const Scanner& work, const Scanner& initial, const std::string& source,
                            const StepRunner& run) {
  if (work.kind() != ScannerKind::kMems) {
    throw Error(source + ": the mems step calibrates a MEMS scanner; this one is a galvanometer");
  }
  const StepRunner::PlaneData planes = run.Planes(work.camera());
  const MemsCalibrationResult r =
      CalibrateMemsProjection(work.camera(), planes.planes, planes.dots);
  CalibrationStepOutcome out;
  out.scanner = initial;
  out.scanner.mems().functions = r.functions;
  out.scanner.mems().functions_from_file = true;
  StepRecord& rec = out.record;
  rec.residual_unit = "%";
  rec.observations = r.dots;
  for (int i = 0; i < 6; ++i) {
    std::string f = "f";  // built by += : GCC 12 reports a false -Wrestrict on "f" + string
    f += std::to_string(i + 1);
    rec.params.push_back(
        {f + ".max_percent_error", r.errors[static_cast<size_t>(i)].max_percent, 0.0});
    rec.params.push_back(
        {f + ".mean_percent_error", r.errors[static_cast<size_t>(i)].mean_percent, 0.0});
    rec.residual_rms = std::max(rec.residual_rms, r.errors[static_cast<size_t>(i)].mean_percent);
    rec.residual_max = std::max(rec.residual_max, r.errors[static_cast<size_t>(i)].max_percent);
  }
  rec.params.push_back({"line_rms_m", r.line_rms_m, 0.0});
  out.summary.push_back(Format("%.0f dots, %.0f voltage lines (line rms %.3f mm)", r.dots,
                               r.lines.size(), r.line_rms_m * 1e3));
  out.summary.push_back(Format("f1..f6 fitting error: worst %.4f %%, mean up to %.4f %%",
                               rec.residual_max, rec.residual_rms));
  return out;
}

}  // namespace

CalibrationStepOutcome RunCalibrationStep(const std::string& step,
                                          const CalibrationDataset& dataset, const Scanner& initial,
                                          const std::string& initial_source,
                                          const std::function<void(double)>& progress,
                                          const CalibrationStepOptions& options) {
  const std::vector<std::string>& names = CalibrationSteps();
  if (std::find(names.begin(), names.end(), step) == names.end()) {
    throw Error("calibrate: unknown step '" + step +
                "' (intrinsics, viewport, laser, laser_viewport, mems)");
  }
  if (dataset.step != step) {
    throw Error(dataset.folder.string() + ": a dataset for step '" + dataset.step + "', not '" +
                step + "'");
  }
  const Clock::time_point start = Clock::now();
  const StepRunner run(dataset, progress);
  const Scanner work = ScannerInMedium(initial, dataset.water_refractive_index);
  CalibrationStepOutcome out;
  if (step == "intrinsics") {
    out = Intrinsics(dataset, initial, run);
  } else if (step == "viewport") {
    out = Viewport(dataset, work, initial, run, options);
  } else if (step == "laser" || step == "laser_viewport") {
    out = Laser(work, initial, initial_source, run, step == "laser_viewport", options);
  } else {
    out = Mems(work, initial, initial_source, run);
  }
  out.record.step = step;
  out.record.dataset = std::filesystem::absolute(dataset.folder).lexically_normal().string();
  out.record.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  out.record.date_utc = NowUtc();
  SetStepRecord(&out.scanner, out.record);
  return out;
}

}  // namespace uwscan::scanner::calibration
