#include "perception/features/descriptor_database.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <flann/flann.hpp>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>

#include "perception/features/esf.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/fnv1a.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {

using FlannIndex = flann::Index<flann::ChiSquareDistance<float>>;

struct DescriptorDatabase::Indices {
  std::mutex mutex;  // guards building; built indices are only read
  std::unique_ptr<FlannIndex> exact;
  std::unique_ptr<FlannIndex> approximate;
};

namespace {

constexpr char kMagic[8] = {'U', 'W', 'S', 'C', 'A', 'N', 'D', 'B'};
constexpr std::uint32_t kFormatVersion = 1;
constexpr int kMaxDimension = 1 << 20;
constexpr std::size_t kMaxObjectIdBytes = 4096;
// magic, version, dimension, count; then the checksum at the end.
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8;
constexpr std::size_t kChecksumBytes = 8;

// FLANN's kd-tree draws split dimensions from the global rand(); seeding and building happen
// under this lock so that two databases built at once do not interleave their draws.
std::mutex& FlannRandMutex() {
  static std::mutex mutex;
  return mutex;
}

// Little-endian encoding, independent of the host's byte order.
template <typename U>
void PutUnsigned(std::string& out, U value) {
  for (std::size_t i = 0; i < sizeof(U); ++i) {
    out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
  }
}

void PutFloat(std::string& out, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  PutUnsigned(out, bits);
}

std::string Quoted(const std::filesystem::path& path) {
  return "descriptor database '" + path.string() + "'";
}

// Sequential little-endian reads from a file's bytes; throws naming the file on truncation.
class Reader {
 public:
  Reader(const std::string& bytes, std::size_t end, const std::filesystem::path& path)
      : bytes_(bytes), end_(end), path_(path) {}

  template <typename U>
  U Unsigned(const char* what) {
    Need(sizeof(U), what);
    U value = 0;
    for (std::size_t i = 0; i < sizeof(U); ++i) {
      value |= static_cast<U>(static_cast<unsigned char>(bytes_[pos_ + i])) << (8 * i);
    }
    pos_ += sizeof(U);
    return value;
  }
  float Float(const char* what) {
    const std::uint32_t bits = Unsigned<std::uint32_t>(what);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  std::string String(std::size_t size, const char* what) {
    Need(size, what);
    std::string s = bytes_.substr(pos_, size);
    pos_ += size;
    return s;
  }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return end_ - pos_; }

 private:
  void Need(std::size_t size, const char* what) const {
    if (end_ - pos_ < size) {
      throw Error(Quoted(path_) + ": truncated at byte " + std::to_string(pos_) +
                  " while reading " + what);
    }
  }
  const std::string& bytes_;
  std::size_t end_;
  std::size_t pos_ = 0;
  const std::filesystem::path& path_;
};

// Empty when every value is finite and non-negative, else which value is not.
std::string InvalidValue(std::span<const float> values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return "value " + std::to_string(i) + " is not finite";
    if (values[i] < 0.0f) return "value " + std::to_string(i) + " is negative";
  }
  return {};
}

}  // namespace

void DescriptorIndexOptions::Check() const {
  const OptionChecks check("DescriptorIndexOptions");
  check.InRange("trees", trees, 1, 64);
  check.AtLeast("checks", checks, 1);
}

DescriptorDatabase::DescriptorDatabase(int dimension, const DescriptorIndexOptions& options)
    : dimension_(dimension), options_(options), indices_(std::make_unique<Indices>()) {
  if (dimension < 1 || dimension > kMaxDimension) {
    throw Error("DescriptorDatabase: dimension must be in 1.." + std::to_string(kMaxDimension) +
                ", got " + std::to_string(dimension));
  }
  options_.Check();
}

DescriptorDatabase::DescriptorDatabase(const DescriptorDatabase& other)
    : dimension_(other.dimension_),
      options_(other.options_),
      object_ids_(other.object_ids_),
      view_ids_(other.view_ids_),
      data_(other.data_),
      indices_(std::make_unique<Indices>()) {}

DescriptorDatabase& DescriptorDatabase::operator=(const DescriptorDatabase& other) {
  if (this != &other) {
    DescriptorDatabase copy(other);
    *this = std::move(copy);
  }
  return *this;
}

// The moved-from database is left empty (its indices are rebuilt if it is filled again).
DescriptorDatabase::DescriptorDatabase(DescriptorDatabase&& other) noexcept
    : dimension_(other.dimension_),
      options_(other.options_),
      object_ids_(std::move(other.object_ids_)),
      view_ids_(std::move(other.view_ids_)),
      data_(std::move(other.data_)),
      indices_(std::move(other.indices_)) {
  other.object_ids_.clear();
  other.view_ids_.clear();
  other.data_.clear();
}

DescriptorDatabase& DescriptorDatabase::operator=(DescriptorDatabase&& other) noexcept {
  if (this != &other) {
    dimension_ = other.dimension_;
    options_ = other.options_;
    object_ids_ = std::move(other.object_ids_);
    view_ids_ = std::move(other.view_ids_);
    data_ = std::move(other.data_);
    indices_ = std::move(other.indices_);
    other.object_ids_.clear();
    other.view_ids_.clear();
    other.data_.clear();
  }
  return *this;
}

DescriptorDatabase::~DescriptorDatabase() = default;

std::span<const float> DescriptorDatabase::descriptor(std::size_t entry) const {
  if (entry >= size()) {
    throw Error("DescriptorDatabase::descriptor: entry " + std::to_string(entry) +
                " out of range (size " + std::to_string(size()) + ")");
  }
  return {Row(entry), static_cast<std::size_t>(dimension_)};
}

void DescriptorDatabase::set_index_options(const DescriptorIndexOptions& options) {
  options.Check();
  options_ = options;
  if (indices_) indices_->approximate.reset();
}

void DescriptorDatabase::Add(const std::string& object_id, int view_id,
                             std::span<const float> descriptor) {
  const std::string what =
      "DescriptorDatabase::Add('" + object_id + "', view " + std::to_string(view_id) + ")";
  if (object_id.empty() || object_id.size() > kMaxObjectIdBytes) {
    throw Error(what + ": object id must have 1.." + std::to_string(kMaxObjectIdBytes) +
                " bytes, has " + std::to_string(object_id.size()));
  }
  if (descriptor.size() != static_cast<std::size_t>(dimension_)) {
    throw Error(what + ": descriptor has " + std::to_string(descriptor.size()) +
                " values, the database dimension is " + std::to_string(dimension_));
  }
  if (const std::string bad = InvalidValue(descriptor); !bad.empty()) {
    throw Error(what + ": descriptor " + bad);
  }
  // FLANN indices point into data_, which may move: drop them before changing it.
  indices_ = std::make_unique<Indices>();
  object_ids_.push_back(object_id);
  view_ids_.push_back(view_id);
  data_.insert(data_.end(), descriptor.begin(), descriptor.end());
}

std::vector<Neighbor> DescriptorDatabase::NearestEntries(const float* query, int k,
                                                         SearchMode mode) const {
  if (query == nullptr) throw Error("DescriptorDatabase::Nearest: query is null");
  if (k < 1) throw Error("DescriptorDatabase::Nearest: k must be >= 1, got " + std::to_string(k));
  if (const std::string bad = InvalidValue({query, static_cast<std::size_t>(dimension_)});
      !bad.empty()) {
    throw Error("DescriptorDatabase::Nearest: query " + bad);
  }
  if (empty()) return {};
  const std::size_t knn = std::min(static_cast<std::size_t>(k), size());

  FlannIndex* index = nullptr;
  {
    std::lock_guard<std::mutex> lock(indices_->mutex);
    // flann::Matrix takes a mutable pointer; the indices never write through it.
    const flann::Matrix<float> dataset(const_cast<float*>(data_.data()), size(),
                                       static_cast<std::size_t>(dimension_));
    if (mode == SearchMode::kExact) {
      if (!indices_->exact) {
        indices_->exact = std::make_unique<FlannIndex>(dataset, flann::LinearIndexParams());
        indices_->exact->buildIndex();
      }
      index = indices_->exact.get();
    } else {
      if (!indices_->approximate) {
        std::lock_guard<std::mutex> rand_lock(FlannRandMutex());
        flann::seed_random(static_cast<unsigned int>(options_.seed));
        indices_->approximate =
            std::make_unique<FlannIndex>(dataset, flann::KDTreeIndexParams(options_.trees));
        indices_->approximate->buildIndex();
      }
      index = indices_->approximate.get();
    }
  }

  std::vector<std::size_t> found(knn);
  std::vector<float> found_distances(knn);
  flann::Matrix<std::size_t> found_matrix(found.data(), 1, knn);
  flann::Matrix<float> distance_matrix(found_distances.data(), 1, knn);
  const flann::Matrix<float> query_matrix(const_cast<float*>(query), 1,
                                          static_cast<std::size_t>(dimension_));
  flann::SearchParams params(mode == SearchMode::kExact ? flann::FLANN_CHECKS_UNLIMITED
                                                        : options_.checks);
  const int n = index->knnSearch(query_matrix, found_matrix, distance_matrix, knn, params);

  std::vector<Neighbor> neighbors;
  neighbors.reserve(knn);
  for (int i = 0; i < n && static_cast<std::size_t>(i) < knn; ++i) {
    if (found[i] >= size()) continue;  // FLANN marks missing results with an invalid index
    neighbors.push_back({found[i], ChiSquareDistance(query, Row(found[i]), dimension_)});
  }
  std::sort(neighbors.begin(), neighbors.end(), [](const Neighbor& a, const Neighbor& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.entry < b.entry;
  });
  return neighbors;
}

std::vector<Match> DescriptorDatabase::Nearest(const float* query, int k, SearchMode mode) const {
  std::vector<Match> matches;
  for (const Neighbor& n : NearestEntries(query, k, mode)) {
    matches.push_back({object_ids_[n.entry], view_ids_[n.entry], n.distance});
  }
  return matches;
}

void DescriptorDatabase::Save(const std::filesystem::path& path) const {
  std::string bytes;
  bytes.reserve(kHeaderBytes + data_.size() * 4 + size() * 16 + kChecksumBytes);
  bytes.append(kMagic, sizeof kMagic);
  PutUnsigned(bytes, kFormatVersion);
  PutUnsigned(bytes, static_cast<std::uint32_t>(dimension_));
  PutUnsigned(bytes, static_cast<std::uint64_t>(size()));
  for (std::size_t e = 0; e < size(); ++e) {
    PutUnsigned(bytes, static_cast<std::uint32_t>(view_ids_[e]));
    PutUnsigned(bytes, static_cast<std::uint32_t>(object_ids_[e].size()));
    bytes += object_ids_[e];
    for (const float v : descriptor(e)) PutFloat(bytes, v);
  }
  PutUnsigned(bytes, Fnv1a64(bytes.data(), bytes.size()));

  WriteFileAtomically(path, bytes);
}

DescriptorDatabase DescriptorDatabase::Load(const std::filesystem::path& path,
                                            int expected_dimension,
                                            const DescriptorIndexOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(Quoted(path) + ": cannot open: " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(Quoted(path) + ": read error");

  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    throw Error(Quoted(path) + ": not a uwscan descriptor database (bad magic)");
  }
  if (bytes.size() < kHeaderBytes + kChecksumBytes) {
    throw Error(Quoted(path) + ": truncated (" + std::to_string(bytes.size()) + " bytes)");
  }
  const std::size_t end = bytes.size() - kChecksumBytes;
  Reader header(bytes, end, path);
  header.String(sizeof kMagic, "magic");
  const auto version = header.Unsigned<std::uint32_t>("format version");
  if (version != kFormatVersion) {
    throw Error(Quoted(path) + ": format version " + std::to_string(version) +
                " is not supported (expected " + std::to_string(kFormatVersion) + ")");
  }
  Reader trailer(bytes, bytes.size(), path);
  trailer.String(end, "entries");
  if (trailer.Unsigned<std::uint64_t>("checksum") != Fnv1a64(bytes.data(), end)) {
    throw Error(Quoted(path) + ": checksum mismatch (corrupt or truncated file)");
  }

  const auto dimension = header.Unsigned<std::uint32_t>("dimension");
  if (dimension < 1 || dimension > static_cast<std::uint32_t>(kMaxDimension)) {
    throw Error(Quoted(path) + ": invalid dimension " + std::to_string(dimension));
  }
  if (expected_dimension > 0 && dimension != static_cast<std::uint32_t>(expected_dimension)) {
    throw Error(Quoted(path) + ": descriptors have dimension " + std::to_string(dimension) +
                ", expected " + std::to_string(expected_dimension));
  }
  const auto count = header.Unsigned<std::uint64_t>("entry count");
  const std::size_t min_entry_bytes = 8 + 1 + 4 * static_cast<std::size_t>(dimension);
  if (count > header.remaining() / min_entry_bytes) {
    throw Error(Quoted(path) + ": entry count " + std::to_string(count) + " does not fit in " +
                std::to_string(header.remaining()) + " bytes");
  }

  DescriptorDatabase db(static_cast<int>(dimension), options);
  db.object_ids_.reserve(count);
  db.view_ids_.reserve(count);
  db.data_.reserve(count * dimension);
  for (std::uint64_t e = 0; e < count; ++e) {
    const std::string entry = "entry " + std::to_string(e);
    db.view_ids_.push_back(static_cast<int>(header.Unsigned<std::uint32_t>("a view id")));
    const auto id_bytes = header.Unsigned<std::uint32_t>("an object id length");
    if (id_bytes < 1 || id_bytes > kMaxObjectIdBytes) {
      throw Error(Quoted(path) + ": " + entry + " has an object id of " + std::to_string(id_bytes) +
                  " bytes (expected 1.." + std::to_string(kMaxObjectIdBytes) + ")");
    }
    db.object_ids_.push_back(header.String(id_bytes, "an object id"));
    for (std::uint32_t i = 0; i < dimension; ++i) db.data_.push_back(header.Float("a descriptor"));
    if (const std::string bad = InvalidValue(db.descriptor(e)); !bad.empty()) {
      throw Error(Quoted(path) + ": " + entry + " descriptor " + bad);
    }
  }
  if (header.remaining() != 0) {
    throw Error(Quoted(path) + ": " + std::to_string(header.remaining()) +
                " unexpected bytes after the last entry");
  }
  return db;
}

RecallResult MeasureRecall(const DescriptorDatabase& db, std::span<const float> queries, int k) {
  const auto dim = static_cast<std::size_t>(db.dimension());
  if (db.empty()) throw Error("MeasureRecall: the database is empty");
  if (k < 1) throw Error("MeasureRecall: k must be >= 1, got " + std::to_string(k));
  if (queries.empty() || queries.size() % dim != 0) {
    throw Error("MeasureRecall: " + std::to_string(queries.size()) +
                " query values are not a positive multiple of the dimension " +
                std::to_string(dim));
  }
  const std::size_t query_count = queries.size() / dim;
  RecallResult result;
  result.queries = static_cast<int>(query_count);
  result.k = static_cast<int>(std::min(static_cast<std::size_t>(k), db.size()));

  // Build both indices outside the timed loops.
  db.NearestEntries(queries.data(), 1, SearchMode::kExact);
  db.NearestEntries(queries.data(), 1, SearchMode::kApproximate);

  using Clock = std::chrono::steady_clock;
  std::vector<std::vector<Neighbor>> exact(query_count), approximate(query_count);
  auto t0 = Clock::now();
  for (std::size_t q = 0; q < query_count; ++q) {
    exact[q] = db.NearestEntries(queries.data() + q * dim, k, SearchMode::kExact);
  }
  auto t1 = Clock::now();
  for (std::size_t q = 0; q < query_count; ++q) {
    approximate[q] = db.NearestEntries(queries.data() + q * dim, k, SearchMode::kApproximate);
  }
  auto t2 = Clock::now();
  result.exact_seconds = std::chrono::duration<double>(t1 - t0).count();
  result.approximate_seconds = std::chrono::duration<double>(t2 - t1).count();

  double sum = 0.0;
  for (std::size_t q = 0; q < query_count; ++q) {
    std::set<std::size_t> truth;
    for (const Neighbor& n : exact[q]) truth.insert(n.entry);
    std::size_t hits = 0;
    for (const Neighbor& n : approximate[q]) hits += truth.count(n.entry);
    sum += static_cast<double>(hits) / static_cast<double>(truth.size());
  }
  result.recall = sum / static_cast<double>(query_count);
  return result;
}

}  // namespace uwscan::perception
