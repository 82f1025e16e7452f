#include "mapping/slam/submap_store.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// Each store's spill file is its own, even with several mappers in one process.
std::filesystem::path NewSpillPath(const std::filesystem::path& folder) {
  static std::atomic<int> counter{0};
  return folder / ("uwscan-submaps-" + std::to_string(::getpid()) + "-" +
                   std::to_string(counter.fetch_add(1)) + ".bin");
}

template <typename T>
void WriteVector(std::ofstream& out, const std::vector<T>& values) {
  const std::uint64_t n = values.size();
  out.write(reinterpret_cast<const char*>(&n), sizeof n);
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(n * sizeof(T)));
}

template <typename T>
void ReadVector(std::ifstream& in, std::vector<T>* values) {
  std::uint64_t n = 0;
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!in || n > (std::uint64_t{1} << 32)) return;
  values->resize(n);
  in.read(reinterpret_cast<char*>(values->data()), static_cast<std::streamsize>(n * sizeof(T)));
}

void WriteCloud(std::ofstream& out, const perception::PointCloud& cloud) {
  out.write(reinterpret_cast<const char*>(cloud.origin.data()), 3 * sizeof(double));
  WriteVector(out, cloud.points);
  WriteVector(out, cloud.normals);
  WriteVector(out, cloud.intensity);
}

void ReadCloud(std::ifstream& in, perception::PointCloud* cloud) {
  in.read(reinterpret_cast<char*>(cloud->origin.data()), 3 * sizeof(double));
  ReadVector(in, &cloud->points);
  ReadVector(in, &cloud->normals);
  ReadVector(in, &cloud->intensity);
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
  if (spill_folder.empty()) return;
  spill_path_ = NewSpillPath(spill_folder);
  std::ofstream create(spill_path_, std::ios::binary | std::ios::trunc);
  if (!create) {
    throw Error("submap store: cannot create the spill file " + spill_path_.string() +
                " (is the folder there and writable?)");
  }
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
  std::ofstream out(spill_path_, std::ios::binary | std::ios::app);
  const std::int64_t offset = static_cast<std::int64_t>(std::filesystem::file_size(spill_path_));
  WriteCloud(out, slot.clouds->cloud);
  WriteCloud(out, slot.clouds->sparse);
  out.flush();
  if (!out) {
    throw Error("submap store: cannot write submap " + std::to_string(index) + " to " +
                spill_path_.string() + " (disk full?)");
  }
  slot.offset = offset;
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
  auto clouds = std::make_shared<SubmapClouds>();
  ReadCloud(in, &clouds->cloud);
  ReadCloud(in, &clouds->sparse);
  if (!in) {
    throw Error("submap store: cannot read submap " + std::to_string(index) + " back from " +
                spill_path_.string());
  }
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
