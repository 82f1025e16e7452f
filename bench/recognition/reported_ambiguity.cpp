#include "bench/recognition/reported_ambiguity.hpp"

#include <numbers>

namespace uwscan::bench {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The offset left once the translation along the answer's reported free slides is taken out.
Eigen::Vector3d OffsetAcrossFreeSlides(Eigen::Vector3d offset,
                                       const perception::RecognizedObject& reported) {
  for (const perception::FreeDirection& f : reported.free_directions) {
    if (f.kind == perception::FreeKind::kUnconstrained &&
        f.motion == perception::FreeMotion::kTranslation)
      offset -= offset.dot(f.axis_S) * f.axis_S;
  }
  return offset;
}

// Whether a pose is within 5 mm and 2 degrees of the truth (modulo symmetry) but for a slide
// along the answer's reported free slides.
bool PosedButForFreeSlides(const perception::SymmetricPoseError& e, const Eigen::Isometry3d& T_S_O,
                           const perception::RecognizedObject& reported) {
  return e.rotation_rad <= 2.0 * kDeg &&
         OffsetAcrossFreeSlides(T_S_O.translation() - e.T_symmetric.translation(), reported)
                 .norm() <= 0.005;
}

}  // namespace

bool PosedButForWhatIsReported(const perception::SymmetricPoseError& e,
                               const Eigen::Isometry3d& T_S_O, const Eigen::Isometry3d& T_S_O_true,
                               const std::vector<Eigen::Vector3d>& points,
                               const perception::ObjectModel& model,
                               const perception::RecognizedObject& reported) {
  if (e.rotation_rad <= 2.0 * kDeg && e.translation_m <= 0.005) return true;
  for (const Eigen::Isometry3d& T : reported.equivalent_poses_S) {
    const perception::SymmetricPoseError other =
        perception::PoseErrorModuloSymmetry(T, T_S_O_true, points, model.symmetries);
    if (other.rotation_rad <= 2.0 * kDeg && other.translation_m <= 0.005) return true;
  }
  if (PosedButForFreeSlides(e, T_S_O, reported)) return true;
  for (const perception::FreeDirection& f : reported.free_directions) {
    if (f.kind != perception::FreeKind::kUnconstrained ||
        f.motion != perception::FreeMotion::kRotation)
      continue;
    for (int degrees = -180; degrees < 180; ++degrees) {
      const Eigen::Isometry3d turn = Eigen::Translation3d(f.point_S) *
                                     Eigen::AngleAxisd(degrees * kDeg, f.axis_S) *
                                     Eigen::Translation3d(-f.point_S);
      const Eigen::Isometry3d turned = turn * T_S_O;
      const perception::SymmetricPoseError t =
          perception::PoseErrorModuloSymmetry(turned, T_S_O_true, points, model.symmetries);
      if (PosedButForFreeSlides(t, turned, reported)) return true;
    }
  }
  return false;
}

}  // namespace uwscan::bench
