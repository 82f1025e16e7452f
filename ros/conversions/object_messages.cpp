#include "ros/conversions/object_messages.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& c) {
  Eigen::Matrix3d m;
  m << 0.0, -c.z(), c.y(), c.z(), 0.0, -c.x(), -c.y(), c.x(), 0.0;
  return m;
}

// A colour per object id, stable from run to run.
Eigen::Vector4f Colour(const std::string& id) {
  std::uint32_t h = 2166136261u;
  for (char c : id) h = (h ^ static_cast<std::uint8_t>(c)) * 16777619u;
  return {0.3F + 0.7F * static_cast<float>(h & 0xFF) / 255.0F,
          0.3F + 0.7F * static_cast<float>((h >> 8) & 0xFF) / 255.0F,
          0.3F + 0.7F * static_cast<float>((h >> 16) & 0xFF) / 255.0F, 1.0F};
}

// The model at its pose and a label above it.
void AddMarkers(const perception::ReportedObject& o, const perception::ObjectModel& model, int id,
                const Header& header, int max_points, std::vector<MarkerMessage>& markers) {
  MarkerMessage points;
  points.header = header;
  points.ns = "uwscan_models";
  points.id = id;
  points.kind = MarkerMessage::Kind::kPoints;
  points.pose = o.T_S_O;
  points.rgba = Colour(o.id);
  const std::size_t stride =
      std::max<std::size_t>(1, model.model.size() / static_cast<std::size_t>(max_points));
  for (std::size_t i = 0; i < model.model.size(); i += stride)
    points.points.push_back(model.model.Point(i).cast<float>());
  markers.push_back(points);
  MarkerMessage label;
  label.header = header;
  label.ns = "uwscan_labels";
  label.id = id;
  label.kind = MarkerMessage::Kind::kText;
  label.pose = o.T_S_O;
  label.pose.translation() -=
      Eigen::Vector3d(0.0, 0.6 * model.diameter_m, 0.0);  // above it (y down)
  char text[96];
  std::snprintf(text, sizeof(text), "%s %.2f", o.id.c_str(), o.score);
  label.text = text;
  label.scale_m = 0.05;
  markers.push_back(label);
}

const perception::ObjectModel& FindModel(const perception::ObjectDatabase& db,
                                         const std::string& id) {
  for (const perception::ObjectModel& m : db.objects) {
    if (m.id == id) return m;
  }
  throw Error("the object database has no object '" + id + "'");
}

}  // namespace

ObjectMessages MakeObjectMessages(const std::vector<perception::ReportedObject>& objects,
                                  const perception::ObjectDatabase& db, const Header& header,
                                  int model_marker_points) {
  ObjectMessages out;
  MarkerMessage clear;
  clear.header = header;
  clear.kind = MarkerMessage::Kind::kDeleteAll;
  out.markers.push_back(clear);
  out.grasps.header = header;
  int id = 0;
  for (const perception::ReportedObject& object : objects) {
    if (!object.recognised()) continue;
    const perception::ObjectModel& model = FindModel(db, object.id);
    AddMarkers(object, model, id++, header, model_marker_points, out.markers);
    out.poses.push_back(PoseMessage{
        header, object.T_S_O,
        ObjectPoseCovariance(object.T_S_O, perception::Centroid(model.model), object.covariance)});
    for (const auto& [name, T_S_G] : object.grasps_S) out.grasps.poses.push_back(T_S_G);
  }
  return out;
}

Covariance6d ObjectPoseCovariance(const Eigen::Isometry3d& T_S_O, const Eigen::Vector3d& c,
                                  const Eigen::Matrix<double, 6, 6>& covariance) {
  // The object's origin moves by R (v + c x w), its orientation by R w about the scan's axes.
  const Eigen::Matrix3d R = T_S_O.rotation();
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
  J.topLeftCorner<3, 3>() = R * Skew(c);
  J.topRightCorner<3, 3>() = R;
  J.bottomLeftCorner<3, 3>() = R;
  return J * covariance * J.transpose();
}

}  // namespace uwscan::ros
