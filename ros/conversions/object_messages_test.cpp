#include "ros/conversions/object_messages.hpp"

#include <gtest/gtest.h>

#include <random>

#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"

namespace uwscan::ros {
namespace {

// [position of the object's origin; rotation vector about the scan's axes] of T_S_O moved by
// recognition's perturbation [w; v] (x -> x + w x (x - c) + v in the object frame, exactly: a
// rotation by |w| about c, then v).
Eigen::Matrix<double, 6, 1> Perturbed(const Eigen::Isometry3d& T_S_O, const Eigen::Vector3d& c,
                                      const Eigen::Matrix<double, 6, 1>& wv) {
  const Eigen::Vector3d w = wv.head<3>(), v = wv.tail<3>();
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  if (w.norm() > 0) delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  delta.translation() = c - delta.linear() * c + v;
  const Eigen::Isometry3d moved = T_S_O * delta;
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = moved.translation() - T_S_O.translation();
  const Eigen::AngleAxisd turn(moved.rotation() * T_S_O.rotation().transpose());
  out.tail<3>() = turn.angle() * turn.axis();
  return out;
}

TEST(ObjectPoseCovariance, IsTheFirstOrderPropagationOfTheObjectFramePerturbation) {
  std::mt19937 rng(5);
  std::normal_distribution<double> d(0.0, 1.0);
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
  T_S_O.linear() = DrawRotation(rng).toRotationMatrix();
  T_S_O.translation() = DrawVector3(d, rng);
  const Eigen::Vector3d c = 0.2 * DrawVector3(d, rng);
  // The Jacobian by central differences, column by column.
  Eigen::Matrix<double, 6, 6> J;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Zero();
    e(k) = h;
    J.col(k) = (Perturbed(T_S_O, c, e) - Perturbed(T_S_O, c, -e)) / (2 * h);
  }
  Eigen::Matrix<double, 6, 6> A;
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) A(r, k) = d(rng);
  }
  const Eigen::Matrix<double, 6, 6> C = A * A.transpose() * 1e-4;
  const Covariance6d expected = J * C * J.transpose();
  EXPECT_LT((ObjectPoseCovariance(T_S_O, c, C) - expected).norm(), 1e-8 * expected.norm());
}

// Two objects and an unknown segment: a delete-all, then the model and label of each recognised
// object at its pose; one pose each, its covariance propagated; every grasp; a missing model named.
TEST(MakeObjectMessages, DrawsEachRecognisedObjectAtItsPoseAndSkipsTheUnknown) {
  perception::ObjectDatabase db;
  for (const char* id : {"valve", "flange"}) {
    perception::ObjectModel m;
    m.id = id;
    m.diameter_m = 0.3;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 10; ++i) points.emplace_back(0.01 * i, 0.02, 0.0);
    m.model = perception::MakeCloud(points);
    db.objects.push_back(m);
  }
  std::vector<perception::ReportedObject> objects(3);
  objects[0].id = "flange";
  objects[0].T_S_O.translation() = Eigen::Vector3d(0.1, 0.2, 1.0);
  objects[0].covariance = 1e-4 * Eigen::Matrix<double, 6, 6>::Identity();
  objects[0].grasps_S = {{"rim", Eigen::Isometry3d::Identity()},
                         {"neck", Eigen::Isometry3d::Identity()}};
  objects[1].id = "unknown";
  objects[2].id = "valve";
  objects[2].score = 0.8;
  const Header header{12.5, "uwscan_camera"};
  const ObjectMessages m = MakeObjectMessages(objects, db, header, 4);
  ASSERT_EQ(m.markers.size(), 5u);
  EXPECT_EQ(m.markers[0].kind, MarkerMessage::Kind::kDeleteAll);
  EXPECT_EQ(m.markers[1].kind, MarkerMessage::Kind::kPoints);
  EXPECT_EQ(m.markers[1].points.size(), 5u);  // 10 points, every second
  EXPECT_TRUE(m.markers[1].pose.isApprox(objects[0].T_S_O));
  EXPECT_EQ(m.markers[4].text, "valve 0.80");
  ASSERT_EQ(m.poses.size(), 2u);
  EXPECT_EQ(m.poses[0].header.frame_id, "uwscan_camera");
  EXPECT_DOUBLE_EQ(m.poses[0].header.stamp_s, 12.5);
  const Eigen::Vector3d c = perception::Centroid(db.objects[1].model);
  EXPECT_TRUE(m.poses[0].covariance.isApprox(
      ObjectPoseCovariance(objects[0].T_S_O, c, objects[0].covariance)));
  EXPECT_EQ(m.grasps.poses.size(), 2u);
  objects[2].id = "pipe";
  try {
    MakeObjectMessages(objects, db, header, 4);
    ADD_FAILURE() << "a model missing from the database was not refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no object 'pipe'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::ros
