#include "scanner/sim/virtual_scanner.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/sim/effective_scanner.hpp"
#include "scanner/sim/simulator.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::scanner::sim {

void VirtualScannerOptions::Check() const {
  pattern.Check();
  effects.Check();
  const OptionChecks check("VirtualScannerOptions");
  check.Require(std::isfinite(water.refractive_index) && water.refractive_index >= 1.0,
                "water.refractive_index", "a finite value >= 1", water.refractive_index);
  check.Require(!effects.motion, "effects.motion", "off (a static scan has no motion)", "on");
  check.Require(!effects.navigation_drift.on, "effects.navigation_drift",
                "off (a static scan has no navigation)", "on");
}

struct VirtualScanner::Impl {
  Scene scene;  // the scanner, water and effects; objects and pose are set per scan
  Scanner effective;
  std::unique_ptr<Triangulator> triangulator;
};

VirtualScanner::VirtualScanner(const Scanner& scanner, const VirtualScannerOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  if (scanner.kind() != options.pattern.kind) {
    throw Error(std::string("virtual scanner: a ") + ToString(scanner.kind()) +
                " scanner cannot scan a " + ToString(options.pattern.kind) + " pattern");
  }
  Scene& scene = impl_->scene;
  scene.source = "virtual scanner";
  scene.water = options.water;
  scene.scanner.model = scanner;
  scene.scanner.galvo = options.pattern.galvo;
  scene.scanner.mems = options.pattern.mems;
  scene.scanner.sweeps = 1;
  scene.effects = options.effects;
  scene.trajectory.poses = {TrajectoryPose{}};
  impl_->effective = EffectiveScanner(scene);
  const TriangulationMethod method =
      options.method.value_or(DefaultTriangulationMethod(options.pattern.kind));
  TriangulatorBuildOptions build;
  build.table_cache = options.table_cache;
  impl_->triangulator = MakeTriangulator(impl_->effective, options.pattern, method, build);
}

VirtualScanner::~VirtualScanner() = default;

const Scanner& VirtualScanner::scanner() const { return impl_->effective; }

VirtualScan VirtualScanner::Scan(const std::vector<SceneObject>& objects,
                                 const Eigen::Isometry3d& T_W_C, std::uint64_t seed) const {
  Scene scene = impl_->scene;
  scene.objects = objects;
  scene.trajectory.poses = {TrajectoryPose{0.0, T_W_C}};
  scene.seed = seed;
  const Simulator simulator(scene);
  const Eigen::Isometry3d T_C_W = T_W_C.inverse();
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  VirtualScan scan;
  std::vector<TriangulatedPoint> triangulated;
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const SimulatedFrame frame = simulator.Frame(i);
    triangulated.resize(frame.peaks_px.size());
    impl_->triangulator->TriangulateFrame(frame.command, frame.peaks_px, triangulated);
    for (std::size_t k = 0; k < triangulated.size(); ++k) {
      if (!triangulated[k].ok()) continue;
      scan.points_C.push_back(triangulated[k].p_C);
      const bool has_truth = k < frame.truth_W.size() && frame.truth_W[k].allFinite();
      scan.truth_C.push_back(has_truth ? Eigen::Vector3d(T_C_W * frame.truth_W[k]) : nan);
      scan.object_index.push_back(k < frame.object_ids.size() ? frame.object_ids[k] : -1);
    }
  }
  return scan;
}

Eigen::Isometry3d LookAt(const Eigen::Vector3d& eye_W, const Eigen::Vector3d& target_W,
                         const Eigen::Vector3d& up_W) {
  const Eigen::Vector3d z = target_W - eye_W;
  if (!(z.norm() > 0.0)) throw Error("LookAt: the eye and the target coincide");
  const Eigen::Vector3d z_unit = z.normalized();
  // Image y points down, so x = y x z with y = -up projected: x = z x up.
  const Eigen::Vector3d x = z_unit.cross(up_W);
  if (!(x.norm() > 1e-9 * up_W.norm())) {
    throw Error("LookAt: the view direction is parallel to the up direction");
  }
  const Eigen::Vector3d x_unit = x.normalized();
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  T_W_C.linear().col(0) = x_unit;
  T_W_C.linear().col(1) = z_unit.cross(x_unit);
  T_W_C.linear().col(2) = z_unit;
  T_W_C.translation() = eye_W;
  return T_W_C;
}

Eigen::Isometry3d ViewFrom(const Eigen::Vector3d& centre_W, const Eigen::Vector3d& direction,
                           double standoff_m) {
  const Eigen::Vector3d up =
      std::abs(direction.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  return LookAt(centre_W + standoff_m * direction, centre_W, up);
}

std::vector<Eigen::Vector3d> SphereDirections(int count) {
  if (count < 1) throw Error("SphereDirections: count must be >= 1");
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> directions;
  directions.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    directions.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  return directions;
}

}  // namespace uwscan::scanner::sim
