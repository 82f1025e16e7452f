#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace uwscan::perception {

// A database of labelled global descriptors (ESF histograms, for example) searched by
// chi-square distance, sum over bins with a + b > 0 of (a - b)^2 / (a + b) (see
// ChiSquareDistance in esf.hpp), with FLANN.

enum class SearchMode {
  kExact,        // flann::LinearIndex: every entry compared, the true k nearest
  kApproximate,  // flann::KDTreeIndex: randomised kd-trees, a bounded number of leaf checks
};

struct DescriptorIndexOptions {
  int trees = 8;           // randomised kd-trees of the approximate index, 1..64
  int checks = 128;        // leaves visited per approximate query, >= 1 (more: slower, better)
  std::uint64_t seed = 1;  // passed to flann::seed_random before the kd-trees are built
  // Throws uwscan::Error naming the offending field.
  void Check() const;
};

struct Match {
  std::string object_id;
  int view_id = 0;
  double distance = 0.0;  // chi-square distance to the query
};

// A search hit by position in the database.
struct Neighbor {
  std::size_t entry = 0;  // index of the entry, in insertion (file) order
  double distance = 0.0;  // chi-square distance to the query
};

// Descriptors of one fixed dimension, each labelled with an object id and a view id. Entries
// need not be normalised, but must be finite and non-negative (chi-square assumes histograms).
//
// Search indices are built on the first search after a change and reused; const member
// functions may be called from several threads at once, non-const ones may not overlap any
// other call.
//
// Reproducibility of the approximate index: the seed fixes FLANN's choice of split dimensions
// (it seeds the global rand(), under a lock held by this file only), but FLANN 1.9.2 also
// shuffles each tree's points with std::random_device, which no seed controls. Approximate
// results, and so recall, can vary slightly from one build of the index to the next; exact
// results never do.
class DescriptorDatabase {
 public:
  // Throws uwscan::Error unless 1 <= dimension <= 1'048'576 and options pass Check().
  explicit DescriptorDatabase(int dimension, const DescriptorIndexOptions& options = {});
  DescriptorDatabase(const DescriptorDatabase& other);
  DescriptorDatabase& operator=(const DescriptorDatabase& other);
  DescriptorDatabase(DescriptorDatabase&& other) noexcept;
  DescriptorDatabase& operator=(DescriptorDatabase&& other) noexcept;
  ~DescriptorDatabase();

  int dimension() const { return dimension_; }
  std::size_t size() const { return view_ids_.size(); }
  bool empty() const { return view_ids_.empty(); }
  const std::string& object_id(std::size_t entry) const { return object_ids_.at(entry); }
  int view_id(std::size_t entry) const { return view_ids_.at(entry); }
  std::span<const float> descriptor(std::size_t entry) const;

  const DescriptorIndexOptions& index_options() const { return options_; }
  // Drops the approximate index; the next approximate search rebuilds it.
  void set_index_options(const DescriptorIndexOptions& options);

  // Appends an entry. Throws uwscan::Error when the descriptor has the wrong dimension or a
  // negative or non-finite value, or the object id is empty or longer than 4096 bytes.
  void Add(const std::string& object_id, int view_id, std::span<const float> descriptor);

  // The min(k, size()) entries nearest to `query` (dimension() values), nearest first; ties in
  // distance in entry order. Distances are recomputed in double for the reported entries.
  // An empty database gives no matches. Throws uwscan::Error when query is null, k < 1, or the
  // query has a negative or non-finite value.
  std::vector<Neighbor> NearestEntries(const float* query, int k, SearchMode mode) const;
  std::vector<Match> Nearest(const float* query, int k, SearchMode mode) const;

  // Writes a versioned little-endian binary file atomically: a temporary file beside `path`,
  // flushed to disk (fsync), then renamed over it. Layout: "UWSCANDB", u32 format version (1),
  // u32 dimension, u64 entry count; per entry i32 view id, u32 object id length, the object id
  // bytes, dimension x f32; then the u64 FNV-1a hash of everything before it. Throws
  // uwscan::Error naming the file on I/O failure.
  void Save(const std::filesystem::path& path) const;
  // Reads a file written by Save. Throws uwscan::Error naming the file and the problem when
  // it is missing, unreadable, not a descriptor database, of another version, truncated,
  // corrupt (checksum), holds invalid values, or (expected_dimension > 0) has another dimension.
  static DescriptorDatabase Load(const std::filesystem::path& path, int expected_dimension = 0,
                                 const DescriptorIndexOptions& options = {});

 private:
  struct Indices;  // FLANN indices over data_, built lazily
  const float* Row(std::size_t entry) const { return data_.data() + entry * dimension_; }

  int dimension_;
  DescriptorIndexOptions options_;
  std::vector<std::string> object_ids_;
  std::vector<int> view_ids_;
  std::vector<float> data_;  // size() x dimension_, row-major
  std::unique_ptr<Indices> indices_;
};

struct RecallResult {
  int queries = 0;
  int k = 0;                         // neighbours compared per query (min(k, database size))
  double recall = 0.0;               // mean over queries of |approx top-k ∩ exact top-k| / k
  double exact_seconds = 0.0;        // wall time of all exact searches
  double approximate_seconds = 0.0;  // wall time of all approximate searches
};

// recall@k of the approximate index against the exact one. `queries` holds the query
// descriptors one after another (a multiple of db.dimension() values). Indices are built
// before timing starts. Throws uwscan::Error on an empty database, no queries, a query size
// that is not a multiple of the dimension, or k < 1.
RecallResult MeasureRecall(const DescriptorDatabase& db, std::span<const float> queries, int k);

}  // namespace uwscan::perception
