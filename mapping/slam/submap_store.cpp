#include "mapping/slam/submap_store.hpp"

#include <string>

#include "mapping/slam/spill_file.hpp"
#include "scanner/common/byte_io.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// A cloud as uwscan's own binary encoding (scanner/common/byte_io.hpp): origin, then each array
// with its count.
void PutCloud(const perception::PointCloud& cloud, ByteWriter* out) {
  for (int k = 0; k < 3; ++k) out->Put<double>(cloud.origin[k]);
  for (const std::vector<Eigen::Vector3f>* array : {&cloud.points, &cloud.normals}) {
    out->Put<std::uint64_t>(array->size());
    for (const Eigen::Vector3f& v : *array)
      for (int k = 0; k < 3; ++k) out->Put<float>(v[k]);
  }
  out->Put<std::uint64_t>(cloud.intensity.size());
  for (const float i : cloud.intensity) out->Put<float>(i);
}

void GetCloud(ByteReader* in, perception::PointCloud* cloud) {
  for (int k = 0; k < 3; ++k) cloud->origin[k] = in->Get<double>("origin");
  for (std::vector<Eigen::Vector3f>* array : {&cloud->points, &cloud->normals}) {
    array->resize(in->GetCount("vector count", 3 * sizeof(float)));
    for (Eigen::Vector3f& v : *array)
      for (int k = 0; k < 3; ++k) v[k] = in->Get<float>("vector");
  }
  cloud->intensity.resize(in->GetCount("intensity count", sizeof(float)));
  for (float& i : cloud->intensity) i = in->Get<float>("intensity");
}

std::int64_t CloudBytes(const perception::PointCloud& c) {
  return static_cast<std::int64_t>(c.points.capacity() * sizeof(Eigen::Vector3f) +
                                   c.normals.capacity() * sizeof(Eigen::Vector3f) +
                                   c.intensity.capacity() * sizeof(float));
}

}  // namespace

SubmapStore::SubmapStore(const std::filesystem::path& spill_folder, int resident)
    : resident_(resident) {
  if (resident <= 0)
    throw Error("submap store: resident must be > 0, got " + std::to_string(resident));
  if (!spill_folder.empty()) spill_ = std::make_unique<SpillFile>(spill_folder, "submap store");
}

SubmapStore::~SubmapStore() = default;

void SubmapStore::Add(SubmapClouds clouds) {
  slots_.push_back({std::make_shared<const SubmapClouds>(std::move(clouds)), -1});
  if (spill_ && size() > resident_) Spill(size() - 1 - resident_);
}

void SubmapStore::Spill(int index) {
  Slot& slot = slots_[static_cast<size_t>(index)];
  ByteWriter record;
  PutCloud(slot.clouds->cloud, &record);
  PutCloud(slot.clouds->sparse, &record);
  slot.offset = spill_->Append(record.bytes());
  slot.bytes = static_cast<std::int64_t>(record.bytes().size());
  slot.clouds.reset();
}

std::shared_ptr<const SubmapClouds> SubmapStore::Get(int index) const {
  if (index < 0 || index >= size())
    throw Error("submap store: no submap " + std::to_string(index) + " of " +
                std::to_string(size()));
  const Slot& slot = slots_[static_cast<size_t>(index)];
  if (slot.clouds) return slot.clouds;
  for (auto it = read_back_.begin(); it != read_back_.end(); ++it) {
    if (it->first != index) continue;
    read_back_.splice(read_back_.begin(), read_back_, it);
    return it->second;
  }
  const std::string record = spill_->Read(slot.offset, slot.bytes);
  ByteReader reader(record, 0, record.size(), "submap " + std::to_string(index) + " read back");
  auto clouds = std::make_shared<SubmapClouds>();
  GetCloud(&reader, &clouds->cloud);
  GetCloud(&reader, &clouds->sparse);
  read_back_.emplace_front(index, clouds);
  if (read_back_.size() > kReadBackCache) read_back_.pop_back();
  return clouds;
}

std::int64_t SubmapStore::memory_bytes() const {
  std::int64_t bytes = 0;
  for (const Slot& slot : slots_) {
    if (slot.clouds) bytes += CloudBytes(slot.clouds->cloud) + CloudBytes(slot.clouds->sparse);
  }
  for (const auto& [index, clouds] : read_back_)
    bytes += CloudBytes(clouds->cloud) + CloudBytes(clouds->sparse);
  return bytes;
}

}  // namespace uwscan::mapping
