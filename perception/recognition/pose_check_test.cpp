#include "perception/recognition/pose_check.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/recognition_test_support.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using namespace recognition_test;

// A flange lying on the seabed, scanned, and the segment recognition answered for it.
struct FlangeScan {
  Scan scan;
  std::vector<std::size_t> segment;
};
const FlangeScan& Flange() {
  static const FlangeScan flange = [] {
    FlangeScan f{ScanOnSeabed(CatalogueObject("flange").mesh, Eigen::Vector3d(0.4, -0.3, 0.7), 3),
                 {}};
    const RecognitionResult r = RecognizeObjects(f.scan.cloud, PipeFlangeValveDb());
    const RecognizedObject* nearest = Nearest(r, f.scan);
    if (nearest != nullptr) f.segment = nearest->segment;
    return f;
  }();
  return flange;
}

// At its true pose the flange verifies on its segment and scores as a recognised object does; a
// pipe there fits the neck, not the rim, and scores well below it; the flange turned a quarter
// turn off does not verify, or scores below it too.
TEST(PoseCheck, TheTruePoseVerifiesAndOthersScoreBelowIt) {
  const FlangeScan& f = Flange();
  ASSERT_GT(f.segment.size(), 1000u);
  const ObjectDatabase& db = PipeFlangeValveDb();
  RecognitionCache cache(db);
  const RecognitionCandidate truth =
      CheckObjectPose(f.scan.cloud, f.segment, db, cache, "flange", f.scan.T_S_O);
  EXPECT_EQ(truth.object_id, "flange");
  EXPECT_TRUE(truth.verified);
  EXPECT_GT(truth.score, 0.9);
  // Refined from the truth, it stays there (to the data's scale).
  EXPECT_LT((truth.T_S_O.translation() - f.scan.T_S_O.translation()).norm(), 0.003);
  EXPECT_LT(Eigen::AngleAxisd(truth.T_S_O.linear().transpose() * f.scan.T_S_O.linear()).angle(),
            0.02);

  const RecognitionCandidate pipe =
      CheckObjectPose(f.scan.cloud, f.segment, db, cache, "pipe", f.scan.T_S_O);
  EXPECT_LT(pipe.score, truth.score - 0.05)
      << "fitness " << pipe.fitness << ", close " << pipe.close;

  const Eigen::Isometry3d turned =
      f.scan.T_S_O * Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  const RecognitionCandidate off =
      CheckObjectPose(f.scan.cloud, f.segment, db, cache, "flange", turned);
  EXPECT_FALSE(off.verified && off.score > truth.score - 0.05) << "score " << off.score;
}

TEST(PoseCheck, BadRequestsAreRefusedNamingWhatIsWrong) {
  const FlangeScan& f = Flange();
  const ObjectDatabase& db = PipeFlangeValveDb();
  RecognitionCache cache(db);
  auto message = [&](const std::vector<std::size_t>& segment, const std::string& id,
                     const Eigen::Isometry3d& T_S_O = Flange().scan.T_S_O) {
    try {
      CheckObjectPose(f.scan.cloud, segment, db, cache, id, T_S_O);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(f.segment, "elbow").find("'elbow' is not in the database"), std::string::npos);
  EXPECT_NE(message({}, "flange").find("segment is empty"), std::string::npos);
  EXPECT_NE(message({f.scan.cloud.size()}, "flange").find("past the scan"), std::string::npos);
  Eigen::Isometry3d scaled = f.scan.T_S_O;
  scaled.linear() *= 1.1;
  EXPECT_NE(message(f.segment, "flange", scaled).find("must be finite, a rotation"),
            std::string::npos);
  Eigen::Isometry3d nan = f.scan.T_S_O;
  nan.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(f.segment, "flange", nan).find("must be finite, a rotation"),
            std::string::npos);
}

}  // namespace
}  // namespace uwscan::perception
