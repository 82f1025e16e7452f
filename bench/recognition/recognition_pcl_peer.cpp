#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <limits>

#include "bench/recognition/recognition_peers.hpp"

namespace uwscan::bench {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const perception::PointCloud& cloud,
                                          const Eigen::Vector3d& origin) {
  auto out = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = (cloud.Point(i) - origin).cast<float>();
    out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  return out;
}

}  // namespace

PclEsfPeer::PclEsfPeer(std::vector<PeerObject> objects) : objects_(std::move(objects)) {}

PeerAnswer PclEsfPeer::Recognize(const perception::PointCloud& segment) const {
  PeerAnswer answer{"unknown", Eigen::Isometry3d::Identity()};
  const perception::EsfResult esf = perception::ComputePclEsf(segment);
  if (!esf.ok) return answer;
  double best = std::numeric_limits<double>::infinity();
  const PeerObject* object = nullptr;
  const PeerView* view = nullptr;
  for (const PeerObject& o : objects_) {
    for (const PeerView& v : o.views) {
      const double d = perception::ChiSquareDistance(esf.histogram.data(), v.esf.data(), 640);
      if (d < best) best = d, object = &o, view = &v;
    }
  }
  if (object == nullptr) return answer;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < segment.size(); ++i) centroid += segment.Point(i);
  centroid /= static_cast<double>(segment.size());
  // The object as the view saw it, moved so that the view's centroid lies on the segment's.
  Eigen::Isometry3d T_S_O = view->T_O_C.inverse();
  T_S_O.pretranslate(centroid - view->centroid_C);

  // ICP in coordinates about the segment's centroid (float precision).
  const auto target = ToPcl(segment, centroid);
  const auto source = ToPcl(perception::Transformed(object->model, T_S_O), centroid);
  Eigen::Matrix4f refinement = Eigen::Matrix4f::Identity();
  for (const double distance : {0.02, 0.005}) {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    icp.setInputSource(source);
    icp.setInputTarget(target);
    icp.setMaxCorrespondenceDistance(distance);
    icp.setMaximumIterations(50);
    icp.setTransformationEpsilon(1e-10);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    icp.align(aligned, refinement);
    refinement = icp.getFinalTransformation();
  }
  const Eigen::Isometry3d step(refinement.cast<double>());
  answer.id = object->id;
  answer.T_S_O = Eigen::Translation3d(centroid) * step * Eigen::Translation3d(-centroid) * T_S_O;
  return answer;
}

}  // namespace uwscan::bench
