#include "perception/recognition/object_recognizer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/nearest_grid.hpp"
#include "perception/preprocessing/clustering.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "perception/recognition/recognition_test_support.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/test_cache.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::perception {
namespace {

namespace sim = scanner::sim;
using namespace recognition_test;

TEST(ObjectRecognition, SameDatabaseAndAnswerForOneAndTwoThreads) {
  const ObjectDatabase one = Build({"elbow", "tee"}, 1);
  const ObjectDatabase two = Build({"elbow", "tee"}, 2);
  const std::filesystem::path dir = TestDir();
  one.Save(dir / "uwscan_db_1.db");
  two.Save(dir / "uwscan_db_2.db");
  auto bytes = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(dir / "uwscan_db_1.db"), bytes(dir / "uwscan_db_2.db"));

  // Databases as recognize reads them: from their files (a view pose is stored as a quaternion,
  // so the one in memory differs from it in the last bits).
  const Scan scan = ScanOnSeabed(CatalogueObject("tee").mesh, Eigen::Vector3d(-0.3, 0.6, 0.8), 5);
  const ObjectDatabase loaded = ObjectDatabase::Load(dir / "uwscan_db_1.db");
  RecognitionOptions options;
  options.threads = 1;
  const RecognitionResult a = RecognizeObjects(scan.cloud, loaded, options);
  options.threads = 2;
  const RecognitionResult b = RecognizeObjects(scan.cloud, loaded, options);
  const RecognitionResult c =
      RecognizeObjects(scan.cloud, ObjectDatabase::Load(dir / "uwscan_db_2.db"), options);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  ASSERT_EQ(a.objects.size(), c.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].object_id, b.objects[i].object_id);
    EXPECT_EQ(a.objects[i].object_id, c.objects[i].object_id);
    EXPECT_TRUE(a.objects[i].T_S_O.matrix() == b.objects[i].T_S_O.matrix());
    EXPECT_TRUE(a.objects[i].T_S_O.matrix() == c.objects[i].T_S_O.matrix());
    ASSERT_EQ(a.objects[i].equivalent_poses_S.size(), b.objects[i].equivalent_poses_S.size());
    for (std::size_t k = 0; k < a.objects[i].equivalent_poses_S.size(); ++k) {
      EXPECT_TRUE(a.objects[i].equivalent_poses_S[k].matrix() ==
                  b.objects[i].equivalent_poses_S[k].matrix());
    }
  }
}

TEST(ObjectRecognition, AnObjectNotInTheDatabaseIsUnknown) {
  const Scan elbow = ScanOnSeabed(CatalogueObject("elbow").mesh, Eigen::Vector3d(0.5, 0.2, 0.6), 4);
  const RecognitionResult r = RecognizeObjects(elbow.cloud, PipeFlangeValveDb());
  ASSERT_NE(Nearest(r, elbow), nullptr);
  EXPECT_EQ(Nearest(r, elbow)->object_id, "unknown");
}

// A valve in line with a pipe, touching its end, scanned: objects 1 (pipe) and 2 (valve).
struct TouchingObjects {
  std::vector<sim::SceneObject> scene;
  Eigen::Isometry3d T_W_C;
  sim::VirtualScan scan;
  PointCloud cloud;
};
TouchingObjects PipeAgainstValve() {
  TouchingObjects t;
  const scanner::TriangleMesh pipe = CatalogueObject("pipe").mesh,
                              valve = CatalogueObject("valve_wheel").mesh;
  t.scene = OnSeabed(pipe);
  sim::SceneObject second = OnSeabed(valve)[1];
  // In line with the pipe, the valve's pipe end (120 mm from its centre) against the pipe's end.
  second.T_W_O.translation().y() += 0.36;
  t.scene.push_back(second);
  const Eigen::Vector3d middle =
      0.5 * (t.scene[1].T_W_O.translation() + t.scene[2].T_W_O.translation());
  t.T_W_C = sim::LookAt(middle + Eigen::Vector3d(0.5, 0.1, 0.7), middle, Eigen::Vector3d::UnitZ());
  t.scan = Scanner().Scan(t.scene, t.T_W_C, 11);
  t.cloud = MakeCloud(t.scan.points_C);
  return t;
}

// One Euclidean segment, which neither object explains alone. Both come out, each with its own
// points and pose.
TEST(ObjectRecognition, TwoTouchingObjectsAreBothRecognised) {
  const TouchingObjects touching = PipeAgainstValve();
  const std::vector<sim::SceneObject>& scene = touching.scene;
  const Eigen::Isometry3d& T_W_C = touching.T_W_C;
  const sim::VirtualScan& scan = touching.scan;
  const PointCloud& cloud = touching.cloud;

  // They do touch: their points form one cluster at the recognizer's tolerance.
  std::vector<std::size_t> on_objects;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (scan.object_index[i] >= 1) on_objects.push_back(i);
  }
  ClusteringOptions clustering;
  clustering.tolerance_m = RecognitionOptions{}.cluster_tolerance_m;
  const auto clusters = EuclideanClusters(Subset(cloud, on_objects), clustering);
  ASSERT_FALSE(clusters.empty());
  EXPECT_GT(clusters.front().size(), 0.95 * static_cast<double>(on_objects.size()));

  const RecognitionResult r = RecognizeObjects(cloud, PipeFlangeValveDb());
  for (int o : {1, 2}) {
    const RecognizedObject* holder = nullptr;
    std::size_t most = 0;
    for (const RecognizedObject& found : r.objects) {
      const std::size_t count = static_cast<std::size_t>(
          std::count_if(found.segment.begin(), found.segment.end(),
                        [&](std::size_t i) { return scan.object_index[i] == o; }));
      if (count > most) most = count, holder = &found;
    }
    ASSERT_NE(holder, nullptr);
    const Eigen::Isometry3d T_S_O = T_W_C.inverse() * scene[static_cast<std::size_t>(o)].T_W_O;
    EXPECT_EQ(holder->object_id, o == 1 ? "pipe" : "valve_wheel");
    // The pipe may slide along its axis; across it, and the valve altogether, are pinned.
    Eigen::Vector3d offset = holder->T_S_O.translation() - T_S_O.translation();
    if (o == 1) {
      const Eigen::Vector3d axis_S = T_S_O.linear() * Eigen::Vector3d::UnitZ();
      offset -= offset.dot(axis_S) * axis_S;
    }
    EXPECT_LT(offset.norm(), 0.005) << "object " << o;
  }
}

// The same pipe and valve, the valve's stem left out of its mesh: its handwheel floats 4 cm above
// the body and forms a segment of its own, which cannot join the body's (pipe and body together are
// already wider than any object of the database) and which alone is no object. The segment of the
// body, split off the pipe's, is joined with it and the whole valve comes out, posed.
TEST(ObjectRecognition, AHandwheelCutOffItsValveIsJoinedToIt) {
  TouchingObjects t = PipeAgainstValve();
  const sim::ValveShape shape;
  scanner::TriangleMesh& valve = t.scene[2].mesh;
  std::erase_if(valve.triangles, [&](const Eigen::Vector3i& triangle) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = valve.vertices[triangle[k]];
      if (std::hypot(v.x(), v.z()) > shape.stem_radius_m + 1e-4) return false;
    }
    return true;  // the stem's side and caps
  });
  t.scan = Scanner().Scan(t.scene, t.T_W_C, 11);
  t.cloud = MakeCloud(t.scan.points_C);
  // The wheel's own points: the valve's above the body.
  const Eigen::Isometry3d T_S_O = t.T_W_C.inverse() * t.scene[2].T_W_O;
  std::vector<std::size_t> wheel;
  for (std::size_t i = 0; i < t.cloud.size(); ++i) {
    const double height_O = (T_S_O.inverse() * t.cloud.Point(i)).y();
    if (t.scan.object_index[i] == 2 && height_O > shape.body_radius_m + 0.02) wheel.push_back(i);
  }
  ASSERT_GT(wheel.size(), 300u);
  ClusteringOptions clustering;
  clustering.tolerance_m = RecognitionOptions{}.cluster_tolerance_m;
  std::vector<std::size_t> valve_points;
  for (std::size_t i = 0; i < t.cloud.size(); ++i) {
    if (t.scan.object_index[i] == 2) valve_points.push_back(i);
  }
  EXPECT_GE(EuclideanClusters(Subset(t.cloud, valve_points), clustering).size(), 2u)
      << "the wheel is not cut off";

  const RecognitionResult r = RecognizeObjects(t.cloud, PipeFlangeValveDb());
  const RecognizedObject* holder = nullptr;
  for (const RecognizedObject& found : r.objects) {
    if (std::binary_search(found.segment.begin(), found.segment.end(), wheel.front()))
      holder = &found;
  }
  ASSERT_NE(holder, nullptr);
  ASSERT_EQ(holder->object_id, "valve_wheel");
  const std::size_t held =
      static_cast<std::size_t>(std::count_if(wheel.begin(), wheel.end(), [&](std::size_t i) {
        return std::binary_search(holder->segment.begin(), holder->segment.end(), i);
      }));
  EXPECT_GT(held, 0.95 * static_cast<double>(wheel.size()));
  const ObjectModel& model = PipeFlangeValveDb().objects[2];
  ASSERT_EQ(model.id, "valve_wheel");
  std::vector<Eigen::Vector3d> model_points;
  for (std::size_t i = 0; i < model.model.size(); ++i) model_points.push_back(model.model.Point(i));
  const SymmetricPoseError e =
      PoseErrorModuloSymmetry(holder->T_S_O, T_S_O, model_points, model.symmetries);
  EXPECT_LT(e.translation_m, 0.005);
  EXPECT_LT(e.rotation_rad, 2.0 * std::numbers::pi / 180.0);
}

// The segment split into the objects it holds (in parallel over halves and candidates) gives
// the same objects, points and poses for one thread and two.
TEST(ObjectRecognition, ASplitSegmentIsTheSameForOneAndTwoThreads) {
  const TouchingObjects touching = PipeAgainstValve();
  RecognitionOptions options;
  options.threads = 1;
  const RecognitionResult a = RecognizeObjects(touching.cloud, PipeFlangeValveDb(), options);
  options.threads = 2;
  const RecognitionResult b = RecognizeObjects(touching.cloud, PipeFlangeValveDb(), options);
  EXPECT_TRUE(a.stage_seconds.contains("split")) << "the segment was not split";
  ASSERT_EQ(a.objects.size(), b.objects.size());
  ASSERT_GE(a.objects.size(), 2u);
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].object_id, b.objects[i].object_id);
    EXPECT_EQ(a.objects[i].segment, b.objects[i].segment);
    EXPECT_EQ(a.objects[i].score, b.objects[i].score);
    EXPECT_TRUE(a.objects[i].T_S_O.matrix() == b.objects[i].T_S_O.matrix());
    EXPECT_EQ(a.objects[i].candidates.size(), b.objects[i].candidates.size());
    ASSERT_EQ(a.objects[i].equivalent_poses_S.size(), b.objects[i].equivalent_poses_S.size());
    for (std::size_t k = 0; k < a.objects[i].equivalent_poses_S.size(); ++k) {
      EXPECT_TRUE(a.objects[i].equivalent_poses_S[k].matrix() ==
                  b.objects[i].equivalent_poses_S[k].matrix());
    }
  }
}

// A cache holds the models of the database it was made for: given another, recognition refuses.
TEST(ObjectRecognition, ACacheOfAnotherDatabaseIsRefused) {
  const ObjectDatabase copy = PipeFlangeValveDb();
  RecognitionCache cache(copy);
  const Scan elbow = ScanOnSeabed(CatalogueObject("elbow").mesh, Eigen::Vector3d(0.5, 0.2, 0.6), 4);
  try {
    RecognizeObjects(elbow.cloud, PipeFlangeValveDb(), cache);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("another object database"), std::string::npos) << e.what();
  }
}

// A pipe much longer than the sweep is wide, so its ends are never seen: it is the database's
// pipe, its roll about its axis is a symmetry and its slide along the axis is left free. The roll
// is reported once, as the symmetry it is, not again as a rotation the scan leaves free.
TEST(ObjectRecognition, APipeSeenWithoutItsEndsReportsItsFreeSlideAndRoll) {
  sim::PipeShape shape;
  shape.length_m = 3.0;
  const Scan scan = ScanOnSeabed(sim::MakePipe(shape), Eigen::Vector3d(0.45, 0.0, 0.45), 7);
  const RecognitionResult r = RecognizeObjects(scan.cloud, PipeFlangeValveDb());
  const RecognizedObject* pipe = Nearest(r, scan);
  ASSERT_NE(pipe, nullptr);
  ASSERT_EQ(pipe->object_id, "pipe");
  const Eigen::Vector3d axis_S = scan.T_S_O.linear() * Eigen::Vector3d::UnitZ();
  bool slide = false, roll = false;
  for (const FreeDirection& f : pipe->free_directions) {
    const bool along = std::abs(f.axis_S.dot(axis_S)) > 0.98;
    slide |= f.kind == FreeKind::kUnconstrained && f.motion == FreeMotion::kTranslation && along;
    roll |=
        f.kind == FreeKind::kSymmetry && f.motion == FreeMotion::kRotation && f.order == 0 && along;
    EXPECT_FALSE(f.kind == FreeKind::kUnconstrained && f.motion == FreeMotion::kRotation)
        << "the roll reported twice";
  }
  EXPECT_TRUE(slide);
  EXPECT_TRUE(roll);
  // Across the axis the pose is pinned: the model's axis lies on the true one.
  const Eigen::Vector3d estimated_axis_S = pipe->T_S_O.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(std::abs(estimated_axis_S.dot(axis_S)), std::cos(2.0 * std::numbers::pi / 180.0));
  const Eigen::Vector3d offset = pipe->T_S_O.translation() - scan.T_S_O.translation();
  EXPECT_LT((offset - offset.dot(axis_S) * axis_S).norm(), 0.003);
}

// A database with two pipes of one bore, 0.5 and 0.8 m long: seen without its ends, a long pipe
// is either, and the answer says so; a flange, whose rim the scan would have shown, is not.
TEST(ObjectRecognition, ObjectsTheScanCannotTellApartAreReportedAsEquivalent) {
  ObjectSource pipe = CatalogueObject("pipe");
  ObjectSource long_pipe = pipe;
  long_pipe.id = "pipe_0.8m";
  sim::PipeShape long_shape;
  long_shape.length_m = 0.8;
  long_pipe.mesh = sim::MakePipe(long_shape);
  DatabaseBuildOptions build;
  build.views = 16;
  build.threads = 2;
  const std::vector<ObjectSource> sources = {pipe, long_pipe, CatalogueObject("flange")};
  const ObjectDatabase db = BuildObjectDatabase(sources, Scanner(), build);
  sim::PipeShape shape;
  shape.length_m = 3.0;
  const Scan scan = ScanOnSeabed(sim::MakePipe(shape), Eigen::Vector3d(0.45, 0.0, 0.45), 7);
  const RecognitionResult r = RecognizeObjects(scan.cloud, db);
  const RecognizedObject* found = Nearest(r, scan);
  ASSERT_NE(found, nullptr);
  ASSERT_TRUE(found->object_id == "pipe" || found->object_id == "pipe_0.8m") << found->object_id;
  const std::string other = found->object_id == "pipe" ? "pipe_0.8m" : "pipe";
  ASSERT_EQ(found->equivalent_objects_S.size(), 1u);
  EXPECT_EQ(found->equivalent_objects_S[0].first, other);
  // The alternative's pose lies on the same axis.
  const Eigen::Vector3d axis_S = scan.T_S_O.linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Isometry3d& T_S_other = found->equivalent_objects_S[0].second;
  EXPECT_GT(std::abs((T_S_other.linear() * Eigen::Vector3d::UnitZ()).dot(axis_S)),
            std::cos(2.0 * std::numbers::pi / 180.0));
  const Eigen::Vector3d offset = T_S_other.translation() - scan.T_S_O.translation();
  EXPECT_LT((offset - offset.dot(axis_S) * axis_S).norm(), 0.003);
}

// A flange's bolt heads are its only features about its axis (eight of them: a 45-degree
// period), 8 mm proud of its face: ICP pairs nothing with them unless they already overlap, so
// the phase about the axis must be searched. Rolled by angles across the period, each flange
// is posed within 2 degrees modulo its symmetry.
TEST(ObjectRecognition, AFlangeIsPosedToItsBoltsPhase) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const ObjectSource flange = CatalogueObject("flange");
  ASSERT_TRUE(flange.symmetries.has_value());
  const std::vector<Eigen::Vector3d>& vertices_O = flange.mesh.vertices;
  int posed = 0, seen = 0;
  for (const double phase_deg : {9.0, 17.0, 24.0, 33.0}) {
    const Eigen::Isometry3d roll(Eigen::AngleAxisd(phase_deg * kDeg, Eigen::Vector3d::UnitZ()));
    scanner::TriangleMesh rolled = flange.mesh;
    for (Eigen::Vector3d& v : rolled.vertices) v = roll * v;
    // The flange's face towards the camera, the camera above and off its axis.
    const Scan scan = ScanOnSeabed(rolled, Eigen::Vector3d(0.35, 0.55, 0.55), 21);
    const RecognitionResult r = RecognizeObjects(scan.cloud, PipeFlangeValveDb());
    const RecognizedObject* found = Nearest(r, scan);
    ASSERT_NE(found, nullptr);
    if (found->object_id != "flange") continue;
    ++seen;
    const SymmetricPoseError e =
        PoseErrorModuloSymmetry(found->T_S_O, scan.T_S_O * roll, vertices_O, *flange.symmetries);
    posed += e.rotation_rad < 2.0 * kDeg && e.translation_m < 0.005;
    EXPECT_LT(e.rotation_rad, 2.0 * kDeg) << "rolled " << phase_deg << " degrees";
  }
  EXPECT_EQ(seen, 4);
  EXPECT_EQ(posed, 4);
}

// Seen from its face, a flange is a surface of revolution: its bolt heads are behind the face,
// every phase about its axis fits alike, and its answer reports that turn free (which the ICP's
// information alone did not). Seen from behind, the bolts pin it and it is not reported.
TEST(ObjectRecognition, AFlangeSeenFromItsFaceReportsItsTurnFree) {
  const ObjectSource flange = CatalogueObject("flange");
  auto turn_about_axis_free = [&](const Eigen::Vector3d& eye) {
    const Scan scan = ScanOnSeabed(flange.mesh, eye, 5);
    const RecognitionResult r = RecognizeObjects(scan.cloud, PipeFlangeValveDb());
    const RecognizedObject* found = Nearest(r, scan);
    EXPECT_TRUE(found != nullptr && found->object_id == "flange");
    if (found == nullptr) return false;
    const Eigen::Vector3d axis_S = scan.T_S_O.linear() * Eigen::Vector3d::UnitZ();
    return std::any_of(
        found->free_directions.begin(), found->free_directions.end(), [&](const FreeDirection& f) {
          return f.kind == FreeKind::kUnconstrained && f.motion == FreeMotion::kRotation &&
                 std::abs(f.axis_S.dot(axis_S)) > 0.999;
        });
  };
  // The flange's face is at +z_O, which OnSeabed lays along -y; its neck and bolts face +y.
  EXPECT_TRUE(turn_about_axis_free(Eigen::Vector3d(0.3, -0.6, 0.5)));
  EXPECT_FALSE(turn_about_axis_free(Eigen::Vector3d(0.3, 0.9, 0.5)));
}

// The phase search alone, on the flange's own model: its surface (every third point, 0.5 mm of
// noise) turned 15 degrees about the axis comes back within a degree of the bolts' phase, with
// a residual less than half the turned one; an axis of order 2 has no phase to search.
TEST(ObjectPoseSearch, TheBoltsPhaseIsFound) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const ObjectDatabase& db = PipeFlangeValveDb();
  const auto flange = std::find_if(db.objects.begin(), db.objects.end(),
                                   [](const ObjectModel& o) { return o.id == "flange"; });
  ASSERT_NE(flange, db.objects.end());
  ASSERT_EQ(flange->symmetries.size(), 1u);
  const SymmetryAxis& bolts = flange->symmetries.front();
  ASSERT_EQ(bolts.order, 8);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.0005);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;
  for (std::size_t i = 0; i < flange->model.size(); i += 3) {
    points.push_back(flange->model.Point(i) + Eigen::Vector3d{noise(rng), noise(rng), noise(rng)});
    normals.push_back(flange->model.normals[i]);
  }
  PointCloud sample = MakeCloud(points);
  sample.normals = normals;
  const double voxel_m = db.parameters.voxel_m;
  const NearestGrid index(flange->model.points, voxel_m, 4.0 * voxel_m);
  // The truth is the identity (the sample is in the object's frame); the estimate is turned.
  auto phase_error_rad = [&](const Eigen::Isometry3d& T_O_S) {
    const double angle = Eigen::AngleAxisd(T_O_S.linear()).angle();
    const double period = 2.0 * std::numbers::pi / bolts.order;
    return std::abs(std::remainder(angle, period));
  };
  const Eigen::Isometry3d off(Eigen::AngleAxisd(15.0 * kDeg, bolts.axis_O));
  const std::vector<Eigen::Isometry3d> starts =
      SymmetryPhaseStarts(sample, *flange, index, bolts, off, voxel_m);
  ASSERT_FALSE(starts.empty());
  EXPECT_LT(phase_error_rad(starts.front()), 1.0 * kDeg);
  EXPECT_LT(TruncatedResidual(sample, *flange, index, starts.front(), voxel_m),
            0.5 * TruncatedResidual(sample, *flange, index, off, voxel_m));
  const SymmetryAxis half_turn{bolts.point_O, bolts.axis_O, 2};
  EXPECT_TRUE(SymmetryPhaseStarts(sample, *flange, index, half_turn, off, voxel_m).empty());
}

// A pipe whose scan shows one of its ends (the sweep reaches 0.13 m past it), the rest cut off
// 0.12 m short of its middle as by the sweep's other edge (seabed included): the fit of its wall
// leaves the slide along the axis free (it ended 5 cm off), and the end places it. Slid past the
// end, the model would lie where lines of sight went on to the seabed; slid short of it, the
// scan's last points would leave the model. (Cut at the middle, the piece is a flange's neck as
// much as a pipe.)
TEST(ObjectRecognition, APipeSeenWithOneEndIsPlacedByThatEnd) {
  const Scan full = ScanOnSeabed(CatalogueObject("pipe").mesh, Eigen::Vector3d(0.3, 0.2, 0.8), 4);
  const Eigen::Isometry3d T_O_S = full.T_S_O.inverse();
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < full.cloud.size(); ++i) {
    if ((T_O_S * full.cloud.Point(i)).z() > -0.12) kept.push_back(full.cloud.Point(i));
  }
  const PointCloud cloud = MakeCloud(kept);
  const RecognitionResult r = RecognizeObjects(cloud, PipeFlangeValveDb());
  const RecognizedObject* pipe = Nearest(r, full);
  ASSERT_NE(pipe, nullptr);
  ASSERT_EQ(pipe->object_id, "pipe");
  const Eigen::Vector3d axis_S = full.T_S_O.linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d offset = pipe->T_S_O.translation() - full.T_S_O.translation();
  EXPECT_LT(std::abs(offset.dot(axis_S)), 0.005) << "along the axis";
  EXPECT_LT((offset - offset.dot(axis_S) * axis_S).norm(), 0.003) << "across the axis";
}

// A flange lying on its rim, its scan cut 5 cm short of the rim as by the sweep's edge (seabed
// included): its neck, 4.5 cm over the seabed, fits the database's pipe as well as the flange,
// and the answer says so. But the pipe would hang in the water (its clearance over the seabed is
// the rim's radius less the neck's); the flange rests on the seabed, and is the answer. (Seen
// from other sides, the flange's fit can come out end for end, its rim where the scan shows the
// neck's open end; then the pipe is the better fit.)
TEST(ObjectRecognition, AFlangeNeckOverTheSeabedIsAFlangeNotAFloatingPipe) {
  const Scan full =
      ScanOnSeabed(CatalogueObject("flange").mesh, Eigen::Vector3d(-0.3, 0.0, 0.8), 4);
  const Eigen::Isometry3d T_O_S = full.T_S_O.inverse();
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < full.cloud.size(); ++i) {
    if ((T_O_S * full.cloud.Point(i)).z() < 0.08) kept.push_back(full.cloud.Point(i));
  }
  const RecognitionResult r = RecognizeObjects(MakeCloud(kept), PipeFlangeValveDb());
  const RecognizedObject* found = Nearest(r, full);
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found->object_id, "flange");
  bool pipe_fits = false;
  for (const auto& [id, T_S_other] : found->equivalent_objects_S) pipe_fits |= id == "pipe";
  EXPECT_TRUE(pipe_fits) << "the pipe fits the neck as well";
  for (const RecognitionCandidate& c : found->candidates) {
    if (c.object_id == "pipe" && c.verified) {
      EXPECT_GT(c.clearance_m, 0.03) << "the pipe hangs over the seabed";
    }
    if (c.object_id == "flange") {
      EXPECT_LT(std::abs(c.clearance_m), 0.005) << "the flange rests on it";
    }
  }
}

// A lever valve whose lever the scan does not hold (cut off the mesh scanned, as when it lies
// out of the sweep): its body fits the model turned half a turn about the stem as well, and the
// answer says so with an equivalent pose turned about the stem.
TEST(ObjectRecognition, AValveWithoutItsHandleInViewReportsTheTurnAboutItsStem) {
  const ObjectSource lever = CatalogueObject("valve_lever");
  sim::ValveShape shape;
  scanner::TriangleMesh body = lever.mesh;
  std::erase_if(body.triangles, [&](const Eigen::Vector3i& t) {
    const double low =
        std::min({body.vertices[t[0]].y(), body.vertices[t[1]].y(), body.vertices[t[2]].y()});
    return low > shape.stem_length_m -
                     0.011;  // the lever (12 mm thick, 2 mm above the stem) and the stem's cap
  });
  const ObjectDatabase db = Build({"valve_lever"}, 2);
  const Scan scan =
      ScanOnSeabed(body, Eigen::Vector3d(0.05, 0.1, 0.75), 9);  // from above: both sides in view
  const RecognitionResult r = RecognizeObjects(scan.cloud, db);
  const RecognizedObject* found = Nearest(r, scan);
  ASSERT_NE(found, nullptr);
  ASSERT_EQ(found->object_id, "valve_lever");
  const Eigen::Vector3d stem_S = found->T_S_O.linear() * Eigen::Vector3d::UnitY();
  bool turned_about_stem = false;
  for (const Eigen::Isometry3d& T : found->equivalent_poses_S) {
    const Eigen::AngleAxisd turn((T * found->T_S_O.inverse()).linear());
    turned_about_stem |=
        turn.angle() > 170.0 * std::numbers::pi / 180.0 && std::abs(turn.axis().dot(stem_S)) > 0.98;
  }
  EXPECT_TRUE(turned_about_stem) << found->equivalent_poses_S.size() << " equivalent poses";
}

// A tee whose sweep stopped short of one end of its run shows an L: branch and half a run. The
// tee turned half a turn about the L's bisector (branch and run swapped) lays its legs on the
// same places, but not the junction, where the run passes unbroken and the branch ends: seen
// from above, the turned pose scores 0.84 (90 % of the L within 2 mm of it), the right one 0.96.
// The answer is the right pose, and the turn is not offered as an equivalent one.
TEST(ObjectRecognition, ATeeSeenAsAnLIsToldFromItsTurnAboutTheBisectorByItsJunction) {
  const sim::TeeShape shape;
  const Scan full = ScanOnSeabed(CatalogueObject("tee").mesh, Eigen::Vector3d(0.15, -0.1, 0.8), 5);
  // The sweep's edge a straight line on the seabed across the L's bisector (x_O + z_O constant;
  // y_O is up): neither the run's far end nor the ground where the turned tee's would lie is seen.
  const Eigen::Isometry3d T_O_S = full.T_S_O.inverse();
  std::vector<std::size_t> seen;
  for (std::size_t i = 0; i < full.cloud.size(); ++i) {
    const Eigen::Vector3d p_O = T_O_S * full.cloud.Point(i);
    if (p_O.x() + p_O.z() > -shape.outer_radius_m) seen.push_back(i);
  }
  ASSERT_LT(seen.size(), full.cloud.size());
  const RecognitionResult r = RecognizeObjects(Subset(full.cloud, seen), Build({"tee"}, 2));
  const RecognizedObject* found = Nearest(r, full);
  ASSERT_NE(found, nullptr);
  ASSERT_EQ(found->object_id, "tee");

  // How many of the poses reported lie within 3 degrees and 1 cm of `T_S_O`, modulo the tee's
  // half turn about its branch (x_O through the origin).
  std::vector<Eigen::Isometry3d> reported = found->equivalent_poses_S;
  reported.push_back(found->T_S_O);
  const auto times_reported = [&](const Eigen::Isometry3d& T_S_O) {
    const Eigen::Matrix3d about_branch =
        Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
    int count = 0;
    for (const Eigen::Isometry3d& T : reported) {
      for (const Eigen::Matrix3d& S : {Eigen::Matrix3d::Identity().eval(), about_branch}) {
        const double angle =
            Eigen::AngleAxisd((T_S_O.linear() * S).transpose() * T.linear()).angle();
        count += angle < 3.0 * std::numbers::pi / 180.0 &&
                 (T.translation() - T_S_O.translation()).norm() < 0.01;
      }
    }
    return count;
  };
  Eigen::Isometry3d about_bisector = Eigen::Isometry3d::Identity();
  about_bisector.linear() =
      Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d(1, 0, 1).normalized()).toRotationMatrix();
  EXPECT_EQ(times_reported(full.T_S_O), 1) << reported.size() << " poses reported";
  EXPECT_EQ(times_reported(found->T_S_O), 1);  // the answer is that pose
  EXPECT_EQ(times_reported(full.T_S_O * about_bisector), 0) << reported.size() << " poses reported";
}

// Recognition needs nothing but points in the sensor's frame: a scan by another sensor (the
// MEMS scanner; the database was made by the galvanometer scanner) read back from a plain PLY.
TEST(ObjectRecognition, APlainPlyFromAnotherSensorIsRecognised) {
  sim::VirtualScannerOptions options;
  options.pattern.kind = scanner::ScannerKind::kMems;
  options.pattern.mems.lines = 250;
  const sim::VirtualScanner mems(scanner::DefaultScanner(scanner::ScannerKind::kMems), options);
  const scanner::TriangleMesh valve = CatalogueObject("valve_wheel").mesh;
  const Scan truth = ScanOnSeabed(valve, Eigen::Vector3d(0.3, -0.35, 0.6), 3);  // for its pose
  const std::vector<sim::SceneObject> scene = OnSeabed(valve);
  const sim::VirtualScan scan = mems.Scan(scene, scene[1].T_W_O * truth.T_S_O.inverse(), 3);
  const std::filesystem::path ply = TestDir() / "uwscan_mems_valve.ply";
  WriteCloud(ply, MakeCloud(scan.points_C));
  const Scan from_file{ReadCloud(ply), truth.T_S_O};
  const RecognitionResult r = RecognizeObjects(from_file.cloud, PipeFlangeValveDb());
  const RecognizedObject* found = Nearest(r, from_file);
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found->object_id, "valve_wheel");
  EXPECT_LT((found->T_S_O.translation() - truth.T_S_O.translation()).norm(), 0.005);
}

// An intervention panel seen face-on is mostly one plane, larger in the scan than the seabed or
// wall around it: plane removal must not take it for the support. Lying on the seabed and
// mounted on a wall, it is found and posed (modulo its half turn about the face's normal).
TEST(ObjectRecognition, APanelLyingOnTheSeabedOrMountedOnAWallIsFoundNotRemovedAsAPlane) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  static const ObjectDatabase db = Build({"panel", "pipe", "flange"}, 2);
  const ObjectSource panel = CatalogueObject("panel");
  const sim::PanelShape shape;
  sim::SceneObject seabed;
  seabed.name = "seabed";
  seabed.shape = sim::ObjectShape::kPlane;
  seabed.mesh = sim::MakeRectangle(4.0, 4.0);
  // Lying on its back, handles up, turned 20 degrees about the vertical.
  Eigen::Isometry3d lying = Eigen::Isometry3d::Identity();
  lying.linear() = Eigen::AngleAxisd(20.0 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  lying.translation() = Eigen::Vector3d(0.0, 0.0, shape.thickness_m);
  // On a wall (the plane y = 0.3, facing -y), its front facing -y, 0.5 m above the seabed.
  sim::SceneObject wall = seabed;
  wall.name = "wall";
  wall.T_W_O.linear() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  wall.T_W_O.translation() = Eigen::Vector3d(0.0, 0.3, 1.0);
  Eigen::Isometry3d mounted = Eigen::Isometry3d::Identity();
  mounted.linear() = wall.T_W_O.linear();
  mounted.translation() = Eigen::Vector3d(0.1, 0.3 - shape.thickness_m, 0.5);
  struct Case {
    const char* name;
    std::vector<sim::SceneObject> scene;
    Eigen::Isometry3d T_W_O;
    Eigen::Vector3d eye_W;
  };
  const std::vector<Case> cases = {
      {"lying on the seabed", {seabed, Placed(panel.mesh, lying)}, lying, {0.25, -0.35, 0.75}},
      {"mounted on a wall",
       {seabed, wall, Placed(panel.mesh, mounted)},
       mounted,
       {0.3, -0.5, 0.75}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Eigen::Isometry3d T_W_C =
        sim::LookAt(c.eye_W, c.T_W_O.translation(), Eigen::Vector3d::UnitZ());
    const sim::VirtualScan virtual_scan = Scanner().Scan(c.scene, T_W_C, 7);
    const Scan scan{MakeCloud(virtual_scan.points_C), T_W_C.inverse() * c.T_W_O};
    const RecognitionResult r = RecognizeObjects(scan.cloud, db);
    const RecognizedObject* found = Nearest(r, scan);
    ASSERT_NE(found, nullptr);
    EXPECT_EQ(found->object_id, "panel");
    const SymmetricPoseError e =
        PoseErrorModuloSymmetry(found->T_S_O, scan.T_S_O, panel.mesh.vertices, *panel.symmetries);
    EXPECT_LT(e.rotation_rad, 2.0 * kDeg);
    EXPECT_LT(e.translation_m, 0.005);
  }
}

TEST(ObjectDatabaseFile, TruncatedForeignAndNewerFilesGiveOneLineErrors) {
  const std::filesystem::path dir = TestDir();
  const std::filesystem::path good = dir / "uwscan_db_good.db";
  PipeFlangeValveDb().Save(good);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(dir / name, std::ios::binary) << content;
    return dir / name;
  };
  auto message = [](const std::filesystem::path& p) {
    try {
      ObjectDatabase::Load(p);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string newer = bytes;
  newer[9] = 2;
  const std::string truncated =
      message(write("uwscan_db_cut.db", bytes.substr(0, bytes.size() / 2)));
  const std::string foreign = message(write("uwscan_db_foreign.db", "ply\nformat ascii 1.0\n"));
  const std::string version = message(write("uwscan_db_newer.db", newer));
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;
  EXPECT_NE(foreign.find("not an object database"), std::string::npos) << foreign;
  EXPECT_NE(version.find("newer"), std::string::npos) << version;
  for (const std::string& m : {truncated, foreign, version}) {
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  const std::filesystem::path folder = dir / "uwscan_db_folder.db";
  std::filesystem::create_directories(folder);
  EXPECT_NE(message(folder).find("a directory, not a file"), std::string::npos);
  std::filesystem::remove(folder);
  EXPECT_NO_THROW(ObjectDatabase::Load(good));
}

TEST(ObjectSymmetry, FoundFromTheMesh) {
  const std::vector<SymmetryAxis> pipe = DetectSymmetries(CatalogueObject("pipe").mesh);
  ASSERT_FALSE(pipe.empty());
  EXPECT_TRUE(pipe[0].continuous());
  EXPECT_GT(std::abs(pipe[0].axis_O.z()), 0.999);
  const std::vector<SymmetryAxis> elbow = DetectSymmetries(CatalogueObject("elbow").mesh);
  ASSERT_EQ(elbow.size(), 1u);
  EXPECT_EQ(elbow[0].order, 2);
}

// The 95th percentile over samples of `moved` of their distance to the tangent plane of the
// nearest sample of `surface`, metres: near zero when `moved` lies on the surface, whatever
// the sampling (only the distance along the surface's normal counts).
double SurfaceDistanceP95(const scanner::SurfaceSamples& surface, const KnnIndex& index,
                          const std::vector<Eigen::Vector3d>& moved) {
  std::vector<double> distances;
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  for (const Eigen::Vector3d& p : moved) {
    index.Query(p.cast<float>(), 1, nearest, squared);
    const std::size_t q = nearest[0];
    distances.push_back(std::abs(surface.normals[q].dot(p - surface.points[q])));
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() * 95 / 100,
                   distances.end());
  return distances[distances.size() * 95 / 100];
}

TEST(ObjectSymmetry, DeclaredForTheCatalogueHoldOnItsMeshesAndDetectionAgrees) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  for (const std::string& name : CatalogueNames()) {
    SCOPED_TRACE(name);
    const ObjectSource object = CatalogueObject(name);
    ASSERT_TRUE(object.symmetries.has_value());
    const scanner::SurfaceSamples surface = scanner::SampleSurface(object.mesh, 200000, 1);
    const scanner::SurfaceSamples test = scanner::SampleSurface(object.mesh, 2000, 2);
    std::vector<Eigen::Vector3f> surface_f;
    for (const Eigen::Vector3d& p : surface.points) surface_f.push_back(p.cast<float>());
    const KnnIndex index(surface_f);
    auto moved_by = [&](const Eigen::Isometry3d& T) {
      std::vector<Eigen::Vector3d> moved;
      for (const Eigen::Vector3d& p : test.points) moved.push_back(T * p);
      return moved;
    };
    const double unmoved = SurfaceDistanceP95(surface, index, test.points);
    for (const Eigen::Isometry3d& S : SymmetryTransforms(*object.symmetries, 0.5)) {
      EXPECT_LT(SurfaceDistanceP95(surface, index, moved_by(S)), unmoved + 0.1e-3);
    }
    // The test sees an axis 0.5 degrees off: a half turn about it is no symmetry. (Tilted the
    // wrong way, an elbow's bisector only adds a turn about the torus's own axis, which moves
    // the bend along itself: the larger of two perpendicular tilts counts.)
    for (const SymmetryAxis& s : *object.symmetries) {
      const Eigen::Vector3d u = s.axis_O.unitOrthogonal();
      double off = 0.0;
      for (const Eigen::Vector3d& about : {u, s.axis_O.cross(u)}) {
        const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.5 * kDeg, about) * s.axis_O;
        off =
            std::max(off, SurfaceDistanceP95(surface, index,
                                             moved_by(Eigen::Translation3d(s.point_O) *
                                                      Eigen::AngleAxisd(std::numbers::pi, tilted) *
                                                      Eigen::Translation3d(-s.point_O))));
      }
      EXPECT_GT(off, unmoved + 0.2e-3) << "axis " << s.axis_O.transpose();
    }
    // Detection from the mesh, an independent finder, agrees on every axis, except that a
    // half turn perpendicular to a continuous axis may be found about any such perpendicular.
    const std::vector<SymmetryAxis> detected = DetectSymmetries(object.mesh);
    const auto continuous = std::find_if(object.symmetries->begin(), object.symmetries->end(),
                                         [](const SymmetryAxis& s) { return s.continuous(); });
    for (const SymmetryAxis& s : *object.symmetries) {
      const bool any_perpendicular = continuous != object.symmetries->end() && s.order == 2 &&
                                     std::abs(s.axis_O.dot(continuous->axis_O)) < 1e-9;
      const auto same = std::find_if(detected.begin(), detected.end(), [&](const SymmetryAxis& d) {
        if (d.order != s.order) return false;
        if (any_perpendicular)
          return std::abs(d.axis_O.dot(continuous->axis_O)) < std::sin(1.0 * kDeg);
        return std::abs(d.axis_O.dot(s.axis_O)) > std::cos(1.0 * kDeg);
      });
      EXPECT_NE(same, detected.end()) << "axis " << s.axis_O.transpose() << " order " << s.order;
    }
  }
}

TEST(ObjectSymmetry, ARollAboutAContinuousAxisIsNoError) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  // A pipe: continuous about z, two-fold about x. The estimate is rolled about the axis by an
  // angle between two samples of the continuous symmetry and tilted by 0.4 degrees.
  const std::vector<SymmetryAxis> axes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0},
                                          {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 2}};
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 360; i += 10) {
    for (double z = -0.25; z <= 0.25; z += 0.05) {
      points.emplace_back(0.05 * std::cos(i * kDeg), 0.05 * std::sin(i * kDeg), z);
    }
  }
  const Eigen::Isometry3d T_true = Eigen::Translation3d(1.0, -2.0, 3.0) *
                                   Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  const double tilt = 0.4 * kDeg;
  for (const bool flipped : {false, true}) {
    const Eigen::Isometry3d flip(
        Eigen::AngleAxisd(flipped ? std::numbers::pi : 0.0, Eigen::Vector3d::UnitX()));
    const Eigen::Isometry3d T_est = T_true * flip *
                                    Eigen::AngleAxisd(3.7 * kDeg, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX());
    const SymmetricPoseError exact = PoseErrorModuloSymmetry(T_est, T_true, points, axes);
    EXPECT_NEAR(exact.rotation_rad, tilt, 1e-9);
    EXPECT_NEAR(exact.translation_m, 0.0, 1e-9);
    EXPECT_LT(exact.mssd_m, std::hypot(0.25, 0.05) * tilt +
                                1e-9);  // how far the tilt moves a rim point at an end
    // The 5-degree samples alone count the rest of the roll as an error.
    const SymmetricPoseError sampled =
        PoseErrorModuloSymmetry(T_est, T_true, points, SymmetryTransforms(axes));
    EXPECT_GT(sampled.rotation_rad, 1.0 * kDeg);
  }
}

}  // namespace
}  // namespace uwscan::perception
