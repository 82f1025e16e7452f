#include <chrono>
#include <opencv2/core.hpp>
#include <opencv2/surface_matching.hpp>
#include <opencv2/surface_matching/ppf_helpers.hpp>

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

// PPF's best pose (model -> scene) refined by OpenCV's ICP. The ICP moves the segment onto the
// model, not the model onto the segment as OpenCV's sample does: a segment is a partial view, so
// each of its points has a partner on the whole model, while half of the model has none in the
// segment. Its pyramid has 3 levels, not the sample's 8: the coarsest level keeps 1 point in
// 2^(levels-1), and 8 levels leave a handful of points to solve 6 degrees of freedom from. On 14
// of the bench's seed-2 scans the sample's way moved the poses 0.73 m (median) from the truth and
// posed none within 5 mm / 2 degrees; this way 0.15 m and 2 of 17 (PPF alone: 32 degrees, 4 mm).
Eigen::Matrix4d RefinedModelToScene(const cv::Mat& model, const cv::Mat& scene,
                                    const cv::ppf_match_3d::Pose3D& ppf) {
  const cv::Matx44d scene_to_model = ppf.pose.inv();
  const cv::Mat moved = cv::ppf_match_3d::transformPCPose(scene, scene_to_model);
  cv::ppf_match_3d::ICP icp(100, 0.005f, 2.5f, 3);
  double residual = 0.0;
  cv::Matx44d correction;
  icp.registerModelToScene(moved, model, residual, correction);
  const cv::Matx44d refined = (correction * scene_to_model).inv();
  Eigen::Matrix4d pose;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) pose(r, c) = refined(r, c);
  }
  return pose;
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
    const double votes = static_cast<double>(results.front()->numVotes);
    if (votes <= best_votes) continue;
    best_votes = votes;
    answer.id = m.id;
    answer.T_S_O = Eigen::Translation3d(centroid) *
                   Eigen::Isometry3d(RefinedModelToScene(m.points, scene, *results.front()));
  }
  return answer;
}

}  // namespace uwscan::bench
