#include "mapping/slam/submap_store.hpp"

#include <cstdio>
#include <fstream>
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
  if (!spill_folder.empty())
    spill_path_ = NewSpillFile(spill_folder, "uwscan-submaps", "submap store");
}

SubmapStore::~SubmapStore() {
  if (spill_path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove(spill_path_, ignored);
}

void SubmapStore::Add(SubmapClouds clouds) {
  slots_.push_back({std::make_shared<const SubmapClouds>(std::move(clouds)), -1});
  if (!spill_path_.empty() && size() > resident_) Spill(size() - 1 - resident_);
}

void SubmapStore::Spill(int index) {
  Slot& slot = slots_[static_cast<size_t>(index)];
  ByteWriter record;
  PutCloud(slot.clouds->cloud, &record);
  PutCloud(slot.clouds->sparse, &record);
  std::ofstream out(spill_path_, std::ios::binary | std::ios::app);
  const std::int64_t offset = static_cast<std::int64_t>(std::filesystem::file_size(spill_path_));
  out.write(record.bytes().data(), static_cast<std::streamsize>(record.bytes().size()));
  out.flush();
  if (!out) {
    throw Error("submap store: cannot write submap " + std::to_string(index) + " to " +
                spill_path_.string() + " (disk full?)");
  }
  slot.offset = offset;
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
  std::ifstream in(spill_path_, std::ios::binary);
  in.seekg(slot.offset);
  std::string record(static_cast<size_t>(slot.bytes), '\0');
  in.read(record.data(), static_cast<std::streamsize>(record.size()));
  if (!in) {
    throw Error("submap store: cannot read submap " + std::to_string(index) + " back from " +
                spill_path_.string());
  }
  ByteReader reader(record, 0, record.size(), spill_path_.string());
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
