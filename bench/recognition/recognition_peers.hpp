#pragma once
// The peers of `uwscan bench recognition`, given the same segments and the same objects:
// PCL's global pipeline (pcl::ESFEstimation, the nearest view by chi-square, pcl::
// IterativeClosestPoint) and OpenCV's surface matching (ppf_match_3d::PPF3DDetector and its ICP).
// PCL and OpenCV types stay inside their .cpp files.

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/features/esf.hpp"

namespace uwscan::bench {

struct PeerView {
  perception::EsfDescriptor esf;  // the peer's own descriptor of the view's points
  Eigen::Isometry3d T_O_C = Eigen::Isometry3d::Identity();
  Eigen::Vector3d centroid_C = Eigen::Vector3d::Zero();  // of the view's points, camera frame
};

struct PeerObject {
  std::string id;
  perception::PointCloud model;  // object frame, outward normals
  std::vector<PeerView> views;
};

struct PeerAnswer {
  std::string id;  // "unknown" when the peer found nothing
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
};

// PCL's ESF of each segment, the view with the smallest chi-square names the object, its
// camera pose (moved so the view's centroid falls on the segment's) starts PCL's point-to-point
// ICP of the model onto the segment (correspondences within 2 cm, then 5 mm; 50 iterations each).
class PclEsfPeer {
 public:
  explicit PclEsfPeer(std::vector<PeerObject> objects);
  PeerAnswer Recognize(const perception::PointCloud& segment) const;

 private:
  std::vector<PeerObject> objects_;
};

// One PPF3DDetector per object, trained on its model (every 4th point, sampling 0.07 of its
// box, distance step 0.05; OpenCV's sample uses 0.025, and 0.04 already took minutes per object
// here); each segment is matched against every object (scene sampling 1/5, distance 0.05), the
// best pose of each refined by OpenCV's ICP (100 iterations, 8 levels, as OpenCV's sample), and
// the object with the most votes wins.
class PpfPeer {
 public:
  explicit PpfPeer(const std::vector<PeerObject>& objects);
  ~PpfPeer();
  PeerAnswer Recognize(const perception::PointCloud& segment_with_normals) const;
  double training_seconds() const { return training_seconds_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double training_seconds_ = 0.0;
};

}  // namespace uwscan::bench
