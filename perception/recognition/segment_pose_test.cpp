#include "perception/recognition/segment_pose.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "perception/preprocessing/plane_removal.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "perception/recognition/recognition_test_support.hpp"
#include "perception/recognition/scan_segments.hpp"

namespace uwscan::perception {
namespace {

using namespace recognition_test;
using namespace recognition;

// A flange on the seabed scanned, with what recognition works on: the voxelised scan, its
// seabed removed (the flange is all that is left), the scene around it.
struct FlangeSegment {
  Scan scan;
  PointCloud down;
  PlaneRemovalResult removed;
};
const FlangeSegment& Flange() {
  static const FlangeSegment f = [] {
    FlangeSegment s{
        ScanOnSeabed(CatalogueObject("flange").mesh, Eigen::Vector3d(0.6, 0.1, 0.5), 3), {}, {}};
    const ObjectDatabase& db = PipeFlangeValveDb();
    s.down = VoxelDownsample(s.scan.cloud, VoxelFilterOptions{db.parameters.voxel_m});
    s.removed = RemoveSupportPlanes(s.down, db.LargestDiameter(), RecognitionOptions{});
    return s;
  }();
  return f;
}

// The flange posed end for end (a half turn about an axis across its own, its rim where the scan
// shows its neck) is turned back to its true pose, and placed along its axis by what the scan
// shows of it; posed right, it stays.
TEST(SegmentPose, ACandidatePosedAHalfTurnOffIsTurnedBack) {
  const FlangeSegment& f = Flange();
  const ObjectDatabase& db = PipeFlangeValveDb();
  const std::size_t flange =
      static_cast<std::size_t>(std::find_if(db.objects.begin(), db.objects.end(),
                                            [](const ObjectModel& o) { return o.id == "flange"; }) -
                               db.objects.begin());
  ASSERT_LT(flange, db.objects.size());
  RecognitionCache cache(db);
  const RecognitionOptions options;
  const KnnIndex down_index(f.down.points);
  std::map<std::string, double> untimed;
  StageClock clock(untimed);
  const ScanContext ctx{db, options, cache, f.down, down_index, f.removed.planes, clock};
  ASSERT_GT(f.removed.remaining.size(), 500u);
  const SceneAround around = SceneAroundOf(f.removed.remaining, ctx);
  const DescribedSegment described = DescribeSegment(f.removed.remaining, ctx);
  const ObjectModel& model = db.objects[flange];
  std::vector<Eigen::Vector3d> points_O;
  for (std::size_t i = 0; i < model.model.size(); i += 4) points_O.push_back(model.model.Point(i));

  auto posed_at = [&](const Eigen::Isometry3d& T_O_S) {
    PosedObject posed{flange, {}, {}};
    posed.fine = AlignIcp(described.cloud, cache.Model(flange).target, T_O_S,
                          FineIcp(model.diameter_m, db.parameters, 1));
    Verify(described.cloud, model, cache.Model(flange).nearest(), around, posed.fine, ctx,
           posed.candidate);
    return posed;
  };
  const Eigen::Isometry3d end_for_end(
      Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  PosedObject flipped = posed_at(end_for_end * f.scan.T_S_O.inverse());
  const double flipped_score = flipped.candidate.verified ? flipped.candidate.score : 0.0;
  TurnToBetterHalfTurn(described.cloud, around, ctx, flipped);
  ASSERT_TRUE(flipped.candidate.verified);
  EXPECT_GT(flipped.candidate.score, flipped_score + 0.1);
  // Seen from here the flange's neck leaves its slide along the axis to the ICP's drift, as
  // recognition then places it (it does the same for every contender).
  PlaceAlongFreeDirections(described.cloud, around, ctx, flipped);
  const SymmetricPoseError e = PoseErrorModuloSymmetry(flipped.fine.T_target_source.inverse(),
                                                       f.scan.T_S_O, points_O, model.symmetries);
  EXPECT_LT(e.translation_m, 0.003) << "rotation " << e.rotation_rad;
  EXPECT_LT(e.rotation_rad, 2.0 * std::numbers::pi / 180.0) << "modulo the bolts' phase";

  PosedObject right = posed_at(f.scan.T_S_O.inverse());
  const Eigen::Isometry3d before = right.fine.T_target_source;
  TurnToBetterHalfTurn(described.cloud, around, ctx, right);
  EXPECT_TRUE(right.fine.T_target_source.isApprox(before, 1e-12))
      << "a pose no half turn betters stays";
}

}  // namespace
}  // namespace uwscan::perception
