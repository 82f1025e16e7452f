#pragma once

// Mapper's state and the declarations of its steps, shared by the files that define them
// (mapper.cpp: frames, submaps, consecutive registration, the graph; mapper_loops.cpp: loop
// closures). Internal to mapping/slam.

#include <chrono>
#include <deque>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mapping/slam/mapper.hpp"
#include "mapping/slam/navigation_buffer.hpp"
#include "mapping/slam/navigation_uncertainty.hpp"
#include "mapping/slam/registration_information.hpp"
#include "mapping/slam/submap_centre_grid.hpp"
#include "mapping/slam/submap_store.hpp"
#include "perception/registration/registration_result.hpp"

namespace uwscan::mapping {
namespace mapper_steps {

using Clock = std::chrono::steady_clock;

inline double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Appends `cloud` (points and normals) moved by T to `out`, whose origin is 0.
inline void AppendMoved(const perception::PointCloud& cloud, const Eigen::Isometry3d& T,
                        perception::PointCloud* out) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out->points.push_back((T * cloud.Point(i)).cast<float>());
    if (cloud.has_normals()) out->normals.push_back(R * cloud.normals[i]);
  }
}

// What a copy of the pose graph solved to, on a thread of its own.
struct SolvedGraph {
  std::vector<Eigen::Isometry3d> poses;  // every node the copy held, in order
  DeadReckoningCalibration calibration;
};
// A whole solve running beside the dive (MapperOptions::whole_solve_lag_s).
struct WholeSolveBeside {
  std::future<SolvedGraph> solved;  // what the graph's copy solved to (the copy is gone)
  double apply_at_s = 0.0;          // applied at the first submap anchored this late or later
  std::optional<int> oldest_loop;   // the older end of the oldest correcting loop since
};

}  // namespace mapper_steps

struct Mapper::Impl {
  MapperOptions options;
  Eigen::Isometry3d T_V_C;
  NavigationUncertainty uncertainty;
  std::unique_ptr<scanner::Triangulator> triangulator;
  NavigationBuffer navigation;
  std::deque<FrameRecord> waiting;
  bool finished = false;
  Mapper::FramePlacedCallback on_placed;
  Mapper::FrameLeftOutCallback on_left_out;

  // The submap being filled: points in the navigation's world frame, and its frames. Its frames
  // are placed with the navigation corrected by the calibration estimated when it opened, about
  // the navigation's position at its first frame.
  std::vector<Eigen::Vector3d> points_W;
  DeadReckoningCalibration placement;
  Eigen::Vector3d placement_origin_W = Eigen::Vector3d::Zero();
  std::vector<std::pair<std::int64_t, double>> frames;  // index, time
  int first_sweep = 0;
  std::vector<scanner::TriangulatedPoint> triangulated;

  // Submap i has two nodes in the graph: its anchor (the vehicle at its middle frame, which
  // the navigation measures) and its scan (the pose at which its cloud, bent by the navigation
  // that placed its frames, fits the scene best, which registration measures); a distortion
  // edge ties them (SubmapDistortionCovariance). Bending is then a bounded offset per submap,
  // not a step that accumulates along a chain of registrations.
  std::vector<Submap> submaps;  // their clouds are in `store`
  SubmapStore store;
  std::vector<Matrix6d>
      increment_covariance;  // of scan motion T_{i-1,i} in frame i-1 (0 for i = 0)
  PoseGraph graph;
  std::vector<LoopClosure> loops;
  std::vector<InconsistentRegistration> inconsistent_registrations;
  // The accepted loops as shortcuts for later predictions: the covariance of T_a_b, that of the
  // prediction it was tested against fused with its registration. In the order accepted.
  struct LoopShortcut {
    int a;  // the earlier submap
    int b;  // the later one
    Matrix6d covariance;
  };
  std::vector<LoopShortcut> shortcuts;
  // The centres of the submaps a loop search may ask (loop_min_index_gap or more behind the
  // newest) where the graph has them now: placed as they come within the search's reach
  // (PlaceCentres), moved again after every solve that freed them. The largest of their radii
  // bounds the search's first cut (so one wide submap widens every later query: a cost, never a
  // candidate lost).
  SubmapCentreGrid centres{2.0};
  double largest_radius_m = 0.0;
  void PlaceCentres(int from, int to);
  MapperStats stats;
  int since_solve = 0;
  int next_whole_solve_submaps = 0;  // the graph's size at which the next solve is whole
  // A whole solve running beside the dive (MapperOptions::whole_solve_lag_s).
  std::optional<mapper_steps::WholeSolveBeside> beside;

  Impl(const MapperOptions& o, const Eigen::Isometry3d& mount, const NavigationNoise& noise)
      : options(o),
        T_V_C(mount),
        uncertainty(noise),
        store(o.spill_folder, o.resident_submaps),
        graph(o.spill_folder) {}

  // Places the waiting frames the navigation covers, leaves out those it never will; at the
  // end of the dive (`finishing`) also those after its last sample.
  void Drain(bool finishing);
  void Place(const FrameRecord& frame);
  void CloseSubmap();
  void AddToGraph(Submap submap);
  // A submap registered to the ones before it (AddToGraph), step by step.
  struct ConsecutiveRegistration {
    Eigen::Isometry3d anchor_initial = Eigen::Isometry3d::Identity();  // where its nodes start
    Eigen::Isometry3d scan_initial = Eigen::Isometry3d::Identity();
    Matrix6d increment_cov = Matrix6d::Zero();     // of the scan's motion since the previous one
    std::optional<RelativePoseEdge> registration;  // when it was kept
    Matrix6d slides = Matrix6d::Zero();            // how loosely the scan is tied along free slides
  };
  ConsecutiveRegistration RegisterToPrevious(const Submap& submap, int k);
  perception::PointCloud LocalMap(int k) const;
  void AddNodesAndEdges(const Submap& submap, int k, const ConsecutiveRegistration& c);
  void CloseLoopsAndSolve(int k);
  perception::RegistrationResult Register(const Submap& source,
                                          const perception::PointCloud& target,
                                          const Eigen::Isometry3d& T_init,
                                          const Matrix6d& prior_covariance,
                                          const std::vector<double>& distances) const;
  // The registration's own information (its pairs), weak directions removed. It relates the
  // submaps' effective poses, the graph's nodes (SubmapDistortionCovariance).
  // `kept`, when given, receives what the pairs alone pin (KeptDirections).
  Matrix6d RegistrationInformation(const perception::RegistrationResult& r, const Submap& target,
                                   const Submap& source, KeptDirections* kept = nullptr) const;
  // How far a submap's effective pose may sit from its anchor's navigation pose.
  Matrix6d Distortion(const Submap& s, SystematicErrors systematic_errors) const;
  // The navigation's motion between two submaps' effective poses (in a's frame).
  // Everything it may be off by: the scale error and misalignment as noise, as the
  // calibration may still be settling.
  Matrix6d MotionCovariance(const Submap& a, const Submap& b) const;
  // Loop closures (TryLoopClosures), step by step.
  // Where k is expected in j's frame, and how uncertain that is.
  struct LoopPrediction {
    Eigen::Isometry3d T_j_k;
    Matrix6d covariance;
  };
  struct LoopCandidate {
    int j;            // the earlier submap
    double distance;  // between the two centres, as the graph places them now
    LoopPrediction predicted;
  };
  // C(j, k), the covariance of the scans' motion T_j_k along the chain of consecutive
  // increments (sum over i in (j, k] of Ad(T_j_i-1) increment(i) Ad(T_j_i-1)^T), walked down
  // from k one submap at a time as far as asked, and kept for the next question.
  class ChainBack {
   public:
    ChainBack(const Impl& mapper, int k) : mapper_(mapper), k_(k) {}
    const Matrix6d& To(int j);

   private:
    const Impl& mapper_;
    int k_;
    std::vector<Matrix6d> chain_{Matrix6d::Zero()};  // chain_[k - j]
  };
  void TryLoopClosures(int k);
  std::vector<LoopCandidate> LoopCandidates(int k) const;
  // T_j_k as the graph has it, with its covariance: along the chain between them, or through
  // the accepted loop that leaves the fewest consecutive steps to walk (j to its earlier end,
  // its later end to k).
  LoopPrediction Predict(int j, int k, ChainBack* back_from_k) const;
  perception::PointCloud LoopTarget(int j,
                                    int k) const;  // submap j with its neighbours, in j's frame
  std::vector<double> LoopIcpDistances(const LoopPrediction& predicted) const;
  LoopClosure JudgeLoop(const perception::RegistrationResult& r, const LoopCandidate& c,
                        int k) const;
  std::string LoopRejection(const perception::RegistrationResult& r, const KeptDirections& kept,
                            const Matrix6d& information, const Matrix6d& prediction_covariance,
                            const Vector6d& miss, double* chi2) const;
  int FirstFreeSubmap(int k, std::optional<int> oldest_loop) const;
  bool SolvesBeside(int k) const;
  void StartWholeSolveBeside(int k);
  void ApplyWholeSolveBeside();
  // Solves the submaps from first_free_submap on (0: the whole graph); last: the solve at
  // Finish, to the full tolerance.
  void Solve(int first_free_submap, bool last = false);
  static int AnchorNode(int submap) { return 2 * submap; }
  static int ScanNode(int submap) { return 2 * submap + 1; }
  Eigen::Isometry3d AnchorPose(int submap) const { return graph.pose(AnchorNode(submap)); }
  Eigen::Isometry3d ScanPose(int submap) const { return graph.pose(ScanNode(submap)); }
  SystematicErrors systematic() const {
    return options.estimate_dead_reckoning_calibration ? SystematicErrors::kEstimated
                                                       : SystematicErrors::kAsNoise;
  }
  // The navigation at t (held at its ends) with its motion since the submap's first frame
  // corrected by the placement calibration.
  Eigen::Isometry3d PlacementPose(double time_s) const {
    Eigen::Isometry3d T_W_V = navigation.T_W_V(navigation.HeldTime(time_s));
    T_W_V.translation() =
        placement_origin_W + placement.Correct(T_W_V.translation() - placement_origin_W);
    return T_W_V;
  }
};

}  // namespace uwscan::mapping
