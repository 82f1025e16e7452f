#include "mapping/slam/graph_measurements.hpp"

#include <algorithm>
#include <string>

#include "scanner/common/byte_io.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

template <typename Record>
std::int64_t CapacityBytes(const std::vector<Record>& records) {
  return static_cast<std::int64_t>(records.capacity() * sizeof(Record));
}

template <typename Record>
void DropFirstOf(std::size_t count, std::vector<Record>* records) {
  records->erase(records->begin(), records->begin() + static_cast<std::ptrdiff_t>(count));
}

template <int Rows, int Cols>
void PutMatrix(const Eigen::Matrix<double, Rows, Cols>& m, ByteWriter* out) {
  for (Eigen::Index i = 0; i < m.size(); ++i) out->Put<double>(m(i));
}

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> GetMatrix(ByteReader* in, const char* field) {
  Eigen::Matrix<double, Rows, Cols> m;
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = in->Get<double>(field);
  return m;
}

void Put(const GraphMeasurements::Edge& e, ByteWriter* out) {
  out->Put<std::int32_t>(e.from);
  out->Put<std::int32_t>(e.to);
  PutMatrix<4, 1>(e.q_from_to.coeffs(), out);
  PutMatrix<3, 1>(e.t_from_to, out);
  PutMatrix<6, 6>(e.sqrt_information, out);
  out->Put<std::uint8_t>(static_cast<std::uint8_t>(e.robust ? 1 : 0));
  out->Put<std::uint8_t>(static_cast<std::uint8_t>(e.dead_reckoned ? 1 : 0));
  out->Put<double>(e.huber_scale);
}

GraphMeasurements::Edge GetEdge(ByteReader* in) {
  GraphMeasurements::Edge e;
  e.from = in->Get<std::int32_t>("edge from");
  e.to = in->Get<std::int32_t>("edge to");
  e.q_from_to.coeffs() = GetMatrix<4, 1>(in, "edge rotation");
  e.t_from_to = GetMatrix<3, 1>(in, "edge translation");
  e.sqrt_information = GetMatrix<6, 6>(in, "edge information");
  e.robust = in->Get<std::uint8_t>("edge robust") != 0;
  e.dead_reckoned = in->Get<std::uint8_t>("edge dead reckoned") != 0;
  e.huber_scale = in->Get<double>("edge huber scale");
  return e;
}

void Put(const DepthPrior& d, ByteWriter* out) {
  out->Put<std::int32_t>(d.node);
  out->Put<double>(d.z_m);
  out->Put<double>(d.sigma_m);
}

DepthPrior GetDepth(ByteReader* in) {
  DepthPrior d;
  d.node = in->Get<std::int32_t>("depth node");
  d.z_m = in->Get<double>("depth");
  d.sigma_m = in->Get<double>("depth sigma");
  return d;
}

void Put(const GravityPrior& g, ByteWriter* out) {
  out->Put<std::int32_t>(g.node);
  PutMatrix<3, 1>(g.down_in_V, out);
  out->Put<double>(g.sigma_rad);
}

GravityPrior GetGravity(ByteReader* in) {
  GravityPrior g;
  g.node = in->Get<std::int32_t>("gravity node");
  g.down_in_V = GetMatrix<3, 1>(in, "gravity down");
  g.sigma_rad = in->Get<double>("gravity sigma");
  return g;
}

void Put(const GraphMeasurements::Prior& p, ByteWriter* out) {
  out->Put<std::int32_t>(p.node);
  PutMatrix<4, 1>(p.q_W_V.coeffs(), out);
  PutMatrix<3, 1>(p.t_W_V, out);
  PutMatrix<6, 6>(p.sqrt_information, out);
}

GraphMeasurements::Prior GetPrior(ByteReader* in) {
  GraphMeasurements::Prior p;
  p.node = in->Get<std::int32_t>("prior node");
  p.q_W_V.coeffs() = GetMatrix<4, 1>(in, "prior rotation");
  p.t_W_V = GetMatrix<3, 1>(in, "prior position");
  p.sqrt_information = GetMatrix<6, 6>(in, "prior information");
  return p;
}

}  // namespace

void GraphMeasurements::Add(const Edge& edge) {
  edges.push_back(edge);
  Record(Kind::kEdge, edges.size(), std::max(edge.from, edge.to));
}

void GraphMeasurements::Add(const DepthPrior& depth) {
  depths.push_back(depth);
  Record(Kind::kDepth, depths.size(), depth.node);
}

void GraphMeasurements::Add(const GravityPrior& gravity) {
  gravities.push_back(gravity);
  Record(Kind::kGravity, gravities.size(), gravity.node);
}

void GraphMeasurements::Add(const Prior& prior) {
  priors.push_back(prior);
  Record(Kind::kPrior, priors.size(), prior.node);
}

void GraphMeasurements::AddAll(const GraphMeasurements& other) {
  for (const Entry& entry : other.entries) {
    const auto at = static_cast<std::size_t>(entry.index);
    switch (entry.kind) {
      case Kind::kEdge:
        Add(other.edges[at]);
        break;
      case Kind::kDepth:
        Add(other.depths[at]);
        break;
      case Kind::kGravity:
        Add(other.gravities[at]);
        break;
      case Kind::kPrior:
        Add(other.priors[at]);
        break;
    }
  }
}

void GraphMeasurements::Record(Kind kind, std::size_t records_of_kind, int newest_node) {
  const int so_far =
      entries.empty() ? newest_node : std::max(entries.back().newest_so_far, newest_node);
  entries.push_back({kind, static_cast<int>(records_of_kind) - 1, newest_node, so_far});
}

std::array<int, 2> GraphMeasurements::NodesOf(std::size_t i) const {
  const Entry& entry = entries[i];
  const auto at = static_cast<std::size_t>(entry.index);
  switch (entry.kind) {
    case Kind::kEdge:
      return {edges[at].from, edges[at].to};
    case Kind::kDepth:
      return {depths[at].node, -1};
    case Kind::kGravity:
      return {gravities[at].node, -1};
    case Kind::kPrior:
      return {priors[at].node, -1};
  }
  return {-1, -1};
}

// The measurements before OlderThan(first_node) touch none from first_node on: the search
// starts there, so a window costs what the newest measurements hold, not the whole graph.
std::vector<std::size_t> GraphMeasurements::From(int first_node) const {
  std::vector<std::size_t> indices;
  for (std::size_t i = OlderThan(first_node); i < entries.size(); ++i)
    if (entries[i].newest_node >= first_node) indices.push_back(i);
  return indices;
}

std::size_t GraphMeasurements::OlderThan(int first_node) const {
  const auto end = std::partition_point(
      entries.begin(), entries.end(), [&](const Entry& e) { return e.newest_so_far < first_node; });
  return static_cast<std::size_t>(std::distance(entries.begin(), end));
}

void GraphMeasurements::DropFirst(std::size_t count) {
  std::array<int, 4> dropped{};  // by kind
  for (std::size_t i = 0; i < count; ++i) ++dropped[static_cast<std::size_t>(entries[i].kind)];
  DropFirstOf(count, &entries);
  for (Entry& entry : entries) entry.index -= dropped[static_cast<std::size_t>(entry.kind)];
  DropFirstOf(static_cast<std::size_t>(dropped[0]), &edges);
  DropFirstOf(static_cast<std::size_t>(dropped[1]), &depths);
  DropFirstOf(static_cast<std::size_t>(dropped[2]), &gravities);
  DropFirstOf(static_cast<std::size_t>(dropped[3]), &priors);
}

std::int64_t GraphMeasurements::memory_bytes() const {
  return CapacityBytes(edges) + CapacityBytes(depths) + CapacityBytes(gravities) +
         CapacityBytes(priors) + CapacityBytes(entries);
}

MeasurementSpill::MeasurementSpill(const std::filesystem::path& folder)
    : file_(folder, "pose graph") {}

void MeasurementSpill::Append(const GraphMeasurements& measurements, std::size_t count) {
  ByteWriter record;
  for (std::size_t i = 0; i < count; ++i) {
    const GraphMeasurements::Entry& entry = measurements.entries[i];
    const auto at = static_cast<std::size_t>(entry.index);
    record.Put<std::uint8_t>(static_cast<std::uint8_t>(entry.kind));
    switch (entry.kind) {
      case GraphMeasurements::Kind::kEdge:
        Put(measurements.edges[at], &record);
        break;
      case GraphMeasurements::Kind::kDepth:
        Put(measurements.depths[at], &record);
        break;
      case GraphMeasurements::Kind::kGravity:
        Put(measurements.gravities[at], &record);
        break;
      case GraphMeasurements::Kind::kPrior:
        Put(measurements.priors[at], &record);
        break;
    }
  }
  file_.Append(record.bytes());
  size_ += count;
}

GraphMeasurements MeasurementSpill::ReadAll() const {
  const std::string bytes = file_.Read(0, file_.size());
  ByteReader reader(bytes, 0, bytes.size(), "the pose graph's spilled measurements");
  GraphMeasurements measurements;
  while (!reader.at_end()) {
    switch (static_cast<GraphMeasurements::Kind>(reader.Get<std::uint8_t>("kind"))) {
      case GraphMeasurements::Kind::kEdge:
        measurements.Add(GetEdge(&reader));
        break;
      case GraphMeasurements::Kind::kDepth:
        measurements.Add(GetDepth(&reader));
        break;
      case GraphMeasurements::Kind::kGravity:
        measurements.Add(GetGravity(&reader));
        break;
      case GraphMeasurements::Kind::kPrior:
        measurements.Add(GetPrior(&reader));
        break;
      default:
        reader.Fail("unknown measurement kind");
    }
  }
  if (measurements.size() != size_) {
    reader.Fail("holds " + std::to_string(measurements.size()) + " measurements, " +
                std::to_string(size_) + " were written");
  }
  return measurements;
}

}  // namespace uwscan::mapping
