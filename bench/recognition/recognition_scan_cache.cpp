#include "bench/recognition/recognition_scan_cache.hpp"

#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/fnv1a.hpp"

namespace uwscan::bench {
namespace {

constexpr char kMagic[8] = {'u', 'w', 's', 'c', 'a', 'n', 'S', '1'};  // format version 1

// Header: magic, key, point count; then x y z (double) per point, its object index (int32),
// then the FNV-1a hash of everything before it.
struct Header {
  char magic[8];
  std::uint64_t key;
  std::uint64_t points;
};

std::filesystem::path FileOf(const std::filesystem::path& folder, const CachedScanKey& key) {
  return folder / ("scan_" + std::to_string(key.scan) + ".bin");
}

template <typename T>
void Append(std::string& bytes, const T* data, std::size_t count) {
  bytes.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

}  // namespace

std::optional<scanner::sim::VirtualScan> LoadCachedScan(const std::filesystem::path& folder,
                                                        const CachedScanKey& key) {
  const std::filesystem::path file = FileOf(folder, key);
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto damaged = [&](const std::string& what) {
    return Error("scan cache " + file.string() + ": " + what +
                 " (delete the file to simulate the scan again)");
  };
  Header h;
  if (bytes.size() < sizeof(Header) + sizeof(std::uint64_t)) throw damaged("truncated");
  std::memcpy(&h, bytes.data(), sizeof(Header));
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0)
    throw damaged("not a scan cache of this format version");
  if (h.key != key.key)
    return std::nullopt;  // a scan of other settings: simulated again and replaced
  const std::size_t body = h.points * (3 * sizeof(double) + sizeof(std::int32_t));
  if (h.points > bytes.size() || bytes.size() != sizeof(Header) + body + sizeof(std::uint64_t)) {
    throw damaged("size does not match its point count");
  }
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  if (stored != Fnv1a64(bytes.data(), bytes.size() - sizeof stored))
    throw damaged("checksum mismatch");
  scanner::sim::VirtualScan scan;
  scan.points_C.resize(h.points);
  scan.object_index.resize(h.points);
  const char* p = bytes.data() + sizeof(Header);
  for (Eigen::Vector3d& x : scan.points_C) {
    std::memcpy(x.data(), p, 3 * sizeof(double));
    p += 3 * sizeof(double);
  }
  std::memcpy(scan.object_index.data(), p, h.points * sizeof(std::int32_t));
  return scan;
}

void SaveCachedScan(const std::filesystem::path& folder, const CachedScanKey& key,
                    const scanner::sim::VirtualScan& scan) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error)
    throw Error("scan cache " + folder.string() + ": cannot create the folder: " + error.message());
  if (scan.object_index.size() != scan.points_C.size()) {
    throw Error("scan cache: a scan with " + std::to_string(scan.points_C.size()) + " points has " +
                std::to_string(scan.object_index.size()) + " object indices");
  }
  Header h;
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.key = key.key;
  h.points = scan.points_C.size();
  std::string bytes;
  Append(bytes, &h, 1);
  for (const Eigen::Vector3d& x : scan.points_C) Append(bytes, x.data(), 3);
  Append(bytes, scan.object_index.data(), scan.object_index.size());
  const std::uint64_t sum = Fnv1a64(bytes.data(), bytes.size());
  Append(bytes, &sum, 1);
  const std::filesystem::path file = FileOf(folder, key);
  WriteFileAtomically(file, bytes);
}

}  // namespace uwscan::bench
