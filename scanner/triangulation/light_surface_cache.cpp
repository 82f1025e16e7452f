#include "scanner/triangulation/light_surface_cache.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/fnv1a.hpp"

namespace uwscan::scanner {
namespace {

constexpr char kMagic[8] = {'U', 'W', 'L', 'S', 'T', 'A', 'B', '1'};
// Part of every key: bump it whenever the code that samples or fits the light surfaces
// (SampleFan, FitPlane, FitCone, the laser and refraction models) changes its results, so that
// tables fitted by older code are not served.
constexpr std::int32_t kFittingVersion = 1;

// Bytes appended as they are in memory: the cache is a file of this machine, not an exchange
// format, so native doubles (every bit) are what it compares and returns.
class Bytes {
 public:
  template <typename T>
  void Put(const T& value) {
    const char* p = reinterpret_cast<const char*>(&value);
    data_.insert(data_.end(), p, p + sizeof(T));
  }
  void Put(const Eigen::Isometry3d& T) {
    for (int i = 0; i < 16; ++i) Put(T.matrix().data()[i]);
  }
  void Put(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Put(v[i]);
  }
  std::vector<char>& data() { return data_; }

 private:
  std::vector<char> data_;
};

// Reads what Bytes wrote; every read past the end leaves ok() false.
class Reader {
 public:
  Reader(const std::vector<char>& data, std::size_t start) : data_(data), at_(start) {}
  template <typename T>
  T Get() {
    T value{};
    if (at_ + sizeof(T) > data_.size()) {
      ok_ = false;
      return value;
    }
    std::memcpy(&value, data_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  Eigen::Isometry3d GetPose() {
    Eigen::Isometry3d T;
    for (int i = 0; i < 16; ++i) T.matrix().data()[i] = Get<double>();
    return T;
  }
  Eigen::Vector3d GetVector() {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = Get<double>();
    return v;
  }
  bool ok() const { return ok_; }
  std::size_t at() const { return at_; }

 private:
  const std::vector<char>& data_;
  std::size_t at_;
  bool ok_ = true;
};

// Everything the table depends on, as bits.
std::vector<char> Inputs(const GalvoLaser& laser, const LightSurfaceTableOptions& o) {
  Bytes b;
  b.Put(kFittingVersion);
  b.Put(laser.T_C_L);
  b.Put(laser.T_C_M);
  b.Put(laser.mirror_step_rad);
  b.Put(laser.rotation_distance_m);
  b.Put(laser.aperture_rad);
  b.Put(laser.step_min);
  b.Put(laser.step_max);
  const FlatViewport& v = laser.viewport;
  b.Put(v.normal);
  for (double x : {v.distance_m, v.thickness_m, v.n_air, v.n_glass, v.n_water}) b.Put(x);
  for (double x : {o.depth_min_m, o.depth_max_m}) b.Put(x);
  for (int x : {o.rays_per_fan, o.points_per_ray, o.cone.max_iterations}) b.Put(x);
  for (double x : {o.cone.function_tolerance, o.cone.parameter_tolerance, o.cone.beta_margin_rad})
    b.Put(x);
  for (bool x : {o.fit_cones, o.cone.algebraic_start}) b.Put(x);
  return std::move(b.data());
}

void PutSurfaces(const LightSurfaces& s, Bytes* b) {
  b->Put(s.plane.normal);
  b->Put(s.plane.offset_m);
  b->Put(s.cone.T_C_Q);
  for (double x : {s.cone.a, s.cone.b, s.cone.beta_min_rad, s.cone.beta_max_rad, s.cone.h_min_m,
                   s.plane_rms_m, s.cone_rms_m}) {
    b->Put(x);
  }
  b->Put(s.cone_converged);
}

LightSurfaces GetSurfaces(Reader* r) {
  LightSurfaces s;
  s.plane.normal = r->GetVector();
  s.plane.offset_m = r->Get<double>();
  s.cone.T_C_Q = r->GetPose();
  for (double* x : {&s.cone.a, &s.cone.b, &s.cone.beta_min_rad, &s.cone.beta_max_rad,
                    &s.cone.h_min_m, &s.plane_rms_m, &s.cone_rms_m}) {
    *x = r->Get<double>();
  }
  s.cone_converged = r->Get<bool>();
  return s;
}

// magic, input size, inputs, step_min, count, surfaces, has_cones, checksum of all before it.
std::vector<char> Serialize(const std::vector<char>& inputs, const LightSurfaceTable& table) {
  Bytes b;
  for (char c : kMagic) b.Put(c);
  b.Put(static_cast<std::uint64_t>(inputs.size()));
  b.data().insert(b.data().end(), inputs.begin(), inputs.end());
  b.Put(table.step_min());
  b.Put(static_cast<std::uint64_t>(table.surfaces().size()));
  for (const LightSurfaces& s : table.surfaces()) PutSurfaces(s, &b);
  b.Put(table.has_cones());
  b.Put(Fnv1a64(b.data().data(), b.data().size()));
  return std::move(b.data());
}

// The table in `data` when it was made from exactly `inputs` and is whole; else nullptr.
std::shared_ptr<const LightSurfaceTable> Deserialize(const std::vector<char>& data,
                                                     const std::vector<char>& inputs) {
  constexpr std::size_t kChecksum = sizeof(std::uint64_t);
  if (data.size() < sizeof(kMagic) + 8 + kChecksum ||
      std::memcmp(data.data(), kMagic, sizeof(kMagic)) != 0) {
    return nullptr;
  }
  std::uint64_t stored = 0;
  std::memcpy(&stored, data.data() + data.size() - kChecksum, kChecksum);
  if (stored != Fnv1a64(data.data(), data.size() - kChecksum)) return nullptr;
  Reader r(data, sizeof(kMagic));
  const std::uint64_t input_size = r.Get<std::uint64_t>();
  if (!r.ok() || input_size != inputs.size() || r.at() + input_size > data.size() ||
      std::memcmp(data.data() + r.at(), inputs.data(), inputs.size()) != 0) {
    return nullptr;
  }
  Reader body(data, r.at() + input_size);
  const int step_min = body.Get<int>();
  const std::uint64_t count = body.Get<std::uint64_t>();
  if (!body.ok() || count == 0 || count > 1'000'000) return nullptr;
  std::vector<LightSurfaces> surfaces;
  surfaces.reserve(count);
  for (std::uint64_t i = 0; i < count && body.ok(); ++i) surfaces.push_back(GetSurfaces(&body));
  const bool has_cones = body.Get<bool>();
  if (!body.ok() || body.at() + kChecksum != data.size()) return nullptr;
  return std::make_shared<const LightSurfaceTable>(step_min, std::move(surfaces), has_cones);
}

std::optional<std::vector<char>> ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

// Best effort: a cache that cannot be written is no error, the table is still correct.
void WriteCacheFile(const std::filesystem::path& path, const std::vector<char>& data) {
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  try {
    WriteFileAtomically(path, std::string_view(data.data(), data.size()));
  } catch (const Error&) {
  }
}

}  // namespace

CachedTable LoadOrBuildLightSurfaceTable(const GalvoLaser& laser,
                                         const LightSurfaceTableOptions& options,
                                         const std::filesystem::path& folder) {
  laser.Check();
  options.Check();
  const std::vector<char> inputs = Inputs(laser, options);
  char name[64];
  std::snprintf(name, sizeof(name), "light_surfaces_%016llx.bin",
                static_cast<unsigned long long>(Fnv1a64(inputs.data(), inputs.size())));
  const std::filesystem::path path = folder / name;
  if (const std::optional<std::vector<char>> data = ReadFile(path)) {
    if (std::shared_ptr<const LightSurfaceTable> table = Deserialize(*data, inputs))
      return {table, true};
  }
  auto table = std::make_shared<const LightSurfaceTable>(laser, options);
  WriteCacheFile(path, Serialize(inputs, *table));
  return {table, false};
}

}  // namespace uwscan::scanner
