#include <opencv2/core.hpp>
#include <opencv2/surface_matching.hpp>
#include <opencv2/surface_matching/ppf_helpers.hpp>

#include <chrono>

#include "bench/recognition/recognition_peers.hpp"

namespace uwscan::bench {
namespace {

// Every `stride`-th point as N x 6 float rows (x y z nx ny nz) about `origin`.
cv::Mat ToMat(const perception::PointCloud& cloud, const Eigen::Vector3d& origin,
              std::size_t stride = 1) {
  cv::Mat mat(static_cast<int>((cloud.size() + stride - 1) / stride), 6, CV_32F);
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    const Eigen::Vector3f p = (cloud.Point(i) - origin).cast<float>();
    float* row = mat.ptr<float>(static_cast<int>(i / stride));
    for (int k = 0; k < 3; ++k) row[k] = p[k];
    for (int k = 0; k < 3; ++k) row[3 + k] = cloud.normals[i][k];
  }
  return mat;
}

}  // namespace

struct PpfPeer::Impl {
  struct Model {
    std::string id;
    cv::Mat points;  // about the object frame's origin
    std::unique_ptr<cv::ppf_match_3d::PPF3DDetector> detector;
  };
  std::vector<Model> models;
};

PpfPeer::PpfPeer(const std::vector<PeerObject>& objects) : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  for (const PeerObject& o : objects) {
    Impl::Model m;
    m.id = o.id;
    // OpenCV 4.6 walks a hash bucket to its end before every insertion, and a flat or
    // cylindrical model puts very many point pairs in one bucket: training time grows with the
    // fourth power of the sampled points. Sampling 0.04 of the box took 45 s for the elbow
    // (1196 points) and minutes for the others; 0.07 keeps 660-870 points, 2-13 s per object.
    m.points = ToMat(o.model, Eigen::Vector3d::Zero(), 4);
    m.detector = std::make_unique<cv::ppf_match_3d::PPF3DDetector>(0.07, 0.05);
    m.detector->trainModel(m.points);
    impl_->models.push_back(std::move(m));
  }
  training_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

PpfPeer::~PpfPeer() = default;

PeerAnswer PpfPeer::Recognize(const perception::PointCloud& segment) const {
  PeerAnswer answer{"unknown", Eigen::Isometry3d::Identity()};
  if (!segment.has_normals() || segment.size() < 10) return answer;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < segment.size(); ++i) centroid += segment.Point(i);
  centroid /= static_cast<double>(segment.size());
  const cv::Mat scene = ToMat(segment, centroid);
  double best_votes = -1.0;
  for (const Impl::Model& m : impl_->models) {
    std::vector<cv::ppf_match_3d::Pose3DPtr> results;
    m.detector->match(scene, results, 1.0 / 5.0, 0.05);
    if (results.empty()) continue;
    std::vector<cv::ppf_match_3d::Pose3DPtr> top(results.begin(), results.begin() + 1);
    cv::ppf_match_3d::ICP icp(100, 0.005f, 2.5f, 8);
    icp.registerModelToScene(m.points, scene, top);
    const double votes = static_cast<double>(top[0]->numVotes);
    if (votes <= best_votes) continue;
    best_votes = votes;
    Eigen::Matrix4d pose;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) pose(r, c) = top[0]->pose(r, c);
    }
    answer.id = m.id;
    answer.T_S_O = Eigen::Translation3d(centroid) * Eigen::Isometry3d(pose);
  }
  return answer;
}

}  // namespace uwscan::bench
