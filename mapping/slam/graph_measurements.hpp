#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "mapping/slam/pose_graph.hpp"
#include "mapping/slam/spill_file.hpp"

// The pose graph's measurements as plain records, in the order they were added, and the file
// that the old ones move to on a long dive (MeasurementSpill). Each solve builds its Ceres
// problem from these records (pose_graph.cpp): a Ceres residual block held for every
// measurement, with its cost, loss and bookkeeping, takes several times a record's bytes.
// Internal to mapping/slam.
namespace uwscan::mapping {

struct GraphMeasurements {
  // A RelativePoseEdge with the square root of its information.
  struct Edge {
    int from = 0, to = 0;
    Eigen::Quaterniond q_from_to = Eigen::Quaterniond::Identity();
    Eigen::Vector3d t_from_to = Eigen::Vector3d::Zero();
    Matrix6d sqrt_information = Matrix6d::Zero();
    bool robust = false, dead_reckoned = false;
    double huber_scale = 0.0;
  };
  // A PosePrior with the square root of its information.
  struct Prior {
    int node = 0;
    Eigen::Quaterniond q_W_V = Eigen::Quaterniond::Identity();
    Eigen::Vector3d t_W_V = Eigen::Vector3d::Zero();
    Matrix6d sqrt_information = Matrix6d::Zero();
  };
  enum class Kind : std::uint8_t { kEdge, kDepth, kGravity, kPrior };
  struct Entry {
    Kind kind = Kind::kEdge;
    int index = 0;          // into its kind's records
    int newest_node = 0;    // the highest node it touches
    int newest_so_far = 0;  // the highest node it or any measurement before it touches
  };

  std::vector<Edge> edges;
  std::vector<DepthPrior> depths;
  std::vector<GravityPrior> gravities;
  std::vector<Prior> priors;
  std::vector<Entry> entries;  // every measurement in the order added

  void Add(const Edge& edge);
  void Add(const DepthPrior& depth);
  void Add(const GravityPrior& gravity);
  void Add(const Prior& prior);
  // Adds every measurement of `other` after these, in its order.
  void AddAll(const GraphMeasurements& other);
  std::size_t size() const { return entries.size(); }
  // The nodes measurement i touches (-1: none).
  std::array<int, 2> NodesOf(std::size_t i) const;
  // The measurements that touch a node from first_node on, in the order added.
  std::vector<std::size_t> From(int first_node) const;
  // How many measurements from the first touch no node from first_node on, nor come before
  // one that does: those a solve of the nodes from first_node on never needs.
  std::size_t OlderThan(int first_node) const;
  // Removes the first `count` measurements (after they were spilled).
  void DropFirst(std::size_t count);
  // The bytes the records take in memory (the vectors' capacities).
  std::int64_t memory_bytes() const;

 private:
  // The entry of the record just added, the last of the `records_of_kind` of its kind.
  void Record(Kind kind, std::size_t records_of_kind, int newest_node);
};

// The measurements a long dive's graph no longer needs in memory (GraphMeasurements::OlderThan
// the oldest node a window may free), appended in order to a SpillFile in a folder (nameless
// there: it goes with the spill, or with the process), read back whole for the solves of the
// whole graph.
class MeasurementSpill {
 public:
  // Throws uwscan::Error when the file cannot be created in `folder`.
  explicit MeasurementSpill(const std::filesystem::path& folder);
  MeasurementSpill(const MeasurementSpill&) = delete;
  MeasurementSpill& operator=(const MeasurementSpill&) = delete;

  // Appends the first `count` of `measurements`. Throws uwscan::Error when the write fails.
  void Append(const GraphMeasurements& measurements, std::size_t count);
  // Every measurement appended, in order. Throws uwscan::Error when the file cannot be read.
  GraphMeasurements ReadAll() const;

 private:
  SpillFile file_;
  std::size_t size_ = 0;
};

}  // namespace uwscan::mapping
