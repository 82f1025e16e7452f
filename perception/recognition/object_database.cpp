#include "perception/recognition/object_database.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/byte_io.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/fnv1a.hpp"

namespace uwscan::perception {
namespace {

constexpr char kMagic[] = "UWSCANOBJ";  // 9 bytes written, without the terminating zero
constexpr std::size_t kMagicBytes = sizeof kMagic - 1;
constexpr std::size_t kMaxText = 4096;

void PutPose(ByteWriter& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  for (int i = 0; i < 3; ++i) out.Put<double>(T.translation()[i]);
  out.Put<double>(q.x());
  out.Put<double>(q.y());
  out.Put<double>(q.z());
  out.Put<double>(q.w());
}

void PutVector(ByteWriter& out, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) out.Put<double>(v[i]);
}

double GetFinite(ByteReader& in, const char* field) {
  const double v = in.Get<double>(field);
  if (!std::isfinite(v)) in.Fail(std::string(field) + " is not finite");
  return v;
}

Eigen::Vector3d GetVector(ByteReader& in, const char* field) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = GetFinite(in, field);
  return v;
}

Eigen::Isometry3d GetPose(ByteReader& in, const char* field) {
  const Eigen::Vector3d t = GetVector(in, field);
  const double x = GetFinite(in, field), y = GetFinite(in, field), z = GetFinite(in, field),
               w = GetFinite(in, field);
  const Eigen::Quaterniond q(w, x, y, z);
  if (std::abs(q.norm() - 1.0) > 1e-6) in.Fail(std::string(field) + " has no unit quaternion");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

// A cloud with or without normals (a flag byte says which).
void PutCloud(ByteWriter& out, const PointCloud& cloud) {
  PutVector(out, cloud.origin);
  out.Put<std::uint8_t>(cloud.has_normals() ? 1 : 0);
  out.Put<std::uint64_t>(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int k = 0; k < 3; ++k) out.Put<float>(cloud.points[i][k]);
    if (!cloud.has_normals()) continue;
    for (int k = 0; k < 3; ++k) out.Put<float>(cloud.normals[i][k]);
  }
}

PointCloud GetCloud(ByteReader& in) {
  PointCloud cloud;
  cloud.origin = GetVector(in, "cloud origin");
  const bool normals = in.Get<std::uint8_t>("cloud normals flag") != 0;
  const std::size_t n = in.GetCount("cloud points", normals ? 24 : 12);
  cloud.points.resize(n);
  if (normals) cloud.normals.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) cloud.points[i][k] = in.Get<float>("cloud point");
    if (!cloud.points[i].allFinite()) in.Fail("a cloud point is not finite");
    if (!normals) continue;
    for (int k = 0; k < 3; ++k) cloud.normals[i][k] = in.Get<float>("cloud normal");
    if (!cloud.normals[i].allFinite()) in.Fail("a normal is not finite");
  }
  return cloud;
}

void PutObject(ByteWriter& out, const ObjectModel& o) {
  out.PutString(o.id);
  out.PutString(o.source);
  out.Put<double>(o.diameter_m);
  PutCloud(out, o.model);
  out.Put<std::uint64_t>(o.features.indices.size());
  for (std::size_t i = 0; i < o.features.indices.size(); ++i) {
    out.Put<std::uint64_t>(o.features.indices[i]);
    for (int k = 0; k < 33; ++k) out.Put<float>(o.features.descriptors[i][k]);
  }
  out.Put<std::uint8_t>(o.symmetries_declared ? 1 : 0);
  out.Put<std::uint64_t>(o.symmetries.size());
  for (const SymmetryAxis& s : o.symmetries) {
    PutVector(out, s.point_O);
    PutVector(out, s.axis_O);
    out.Put<std::int32_t>(s.order);
  }
  out.Put<std::uint64_t>(o.grasps.size());
  for (const GraspFrame& g : o.grasps) {
    out.PutString(g.name);
    PutPose(out, g.T_O_G);
  }
  out.Put<std::uint64_t>(o.views.size());
  for (const ObjectView& v : o.views) {
    PutPose(out, v.T_O_C);
    out.Put<std::int32_t>(v.points);
    for (int k = 0; k < 640; ++k) out.Put<float>(v.esf[k]);
    PutCloud(out, v.cloud);
  }
}

ObjectModel GetObject(ByteReader& in) {
  ObjectModel o;
  o.id = in.GetString("object id", kMaxText);
  if (o.id.empty()) in.Fail("an object id is empty");
  o.source = in.GetString("object source", kMaxText);
  o.diameter_m = GetFinite(in, "diameter");
  if (!(o.diameter_m > 0.0)) in.Fail("object '" + o.id + "' has no positive diameter");
  o.model = GetCloud(in);
  if (!o.model.has_normals() || o.model.empty())
    in.Fail("object '" + o.id + "' has no model normals");
  const std::size_t features = in.GetCount("features", 8 + 33 * 4);
  for (std::size_t i = 0; i < features; ++i) {
    const std::uint64_t index = in.Get<std::uint64_t>("feature index");
    if (index >= o.model.size()) in.Fail("a feature index is out of range");
    o.features.indices.push_back(static_cast<std::size_t>(index));
    FpfhDescriptor d;
    for (int k = 0; k < 33; ++k) d[k] = in.Get<float>("feature");
    if (!d.allFinite()) in.Fail("a feature is not finite");
    o.features.descriptors.push_back(d);
  }
  o.symmetries_declared = in.Get<std::uint8_t>("symmetries declared") != 0;
  const std::size_t symmetries = in.GetCount("symmetries", 52);
  for (std::size_t i = 0; i < symmetries; ++i) {
    SymmetryAxis s;
    s.point_O = GetVector(in, "symmetry point");
    s.axis_O = GetVector(in, "symmetry axis");
    s.order = in.Get<std::int32_t>("symmetry order");
    if (std::abs(s.axis_O.norm() - 1.0) > 1e-6 || s.order < 0 || s.order == 1) {
      in.Fail("object '" + o.id + "' has an invalid symmetry");
    }
    o.symmetries.push_back(s);
  }
  const std::size_t grasps = in.GetCount("grasps", 4 + 56);
  for (std::size_t i = 0; i < grasps; ++i) {
    GraspFrame g;
    g.name = in.GetString("grasp name", kMaxText);
    g.T_O_G = GetPose(in, "grasp pose");
    o.grasps.push_back(g);
  }
  const std::size_t views = in.GetCount("views", 56 + 4 + 640 * 4);
  for (std::size_t i = 0; i < views; ++i) {
    ObjectView v;
    v.T_O_C = GetPose(in, "view pose");
    v.points = in.Get<std::int32_t>("view points");
    for (int k = 0; k < 640; ++k) v.esf[k] = in.Get<float>("view ESF");
    if (!v.esf.allFinite() || (v.esf.array() < 0.0f).any()) in.Fail("a view's ESF is invalid");
    v.cloud = GetCloud(in);
    o.views.push_back(v);
  }
  return o;
}

}  // namespace

double ObjectDatabase::LargestDiameter() const {
  double largest_m = 0.0;
  for (const ObjectModel& o : objects) largest_m = std::max(largest_m, o.diameter_m);
  return largest_m;
}

void ObjectDatabase::Save(const std::filesystem::path& path) const {
  ByteWriter out;
  out.bytes().append(kMagic, kMagicBytes);
  out.Put<std::uint32_t>(kObjectDatabaseVersion);
  out.Put<double>(parameters.voxel_m);
  out.Put<double>(parameters.normal_radius_m);
  out.Put<double>(parameters.feature_radius_m);
  out.PutString(parameters.scanner);
  out.Put<std::uint64_t>(objects.size());
  for (const ObjectModel& o : objects) PutObject(out, o);
  const std::uint64_t checksum = Fnv1a64(out.bytes().data(), out.bytes().size());
  out.Put<std::uint64_t>(checksum);
  WriteFileAtomically(path, out.bytes());
}

ObjectDatabase ObjectDatabase::Load(const std::filesystem::path& path) {
  const std::string name = "object database '" + path.string() + "'";
  RequireRegularFile(path, name);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(name + ": cannot be opened (unreadable)");
  std::ostringstream buffer;
  buffer << file.rdbuf();
  const std::string bytes = buffer.str();
  if (bytes.size() < kMagicBytes || bytes.compare(0, kMagicBytes, kMagic) != 0) {
    throw Error(name + ": not an object database (made by `uwscan build-db`)");
  }
  ByteReader header(bytes, kMagicBytes, bytes.size(), name);
  const std::uint32_t version = header.Get<std::uint32_t>("format version");
  if (version != kObjectDatabaseVersion) {
    throw Error(name + ": format version " + std::to_string(version) + ", this uwscan reads " +
                std::to_string(kObjectDatabaseVersion) +
                (version > kObjectDatabaseVersion ? " (made by a newer uwscan)" : "") +
                ": rebuild it with `uwscan build-db`");
  }
  if (bytes.size() < kMagicBytes + 4 + 8) throw Error(name + ": truncated");
  const std::size_t end = bytes.size() - 8;
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + end, 8);
  if (stored != Fnv1a64(bytes.data(), end)) {
    throw Error(name + ": truncated or damaged (checksum mismatch)");
  }
  ByteReader in(bytes, header.position(), end, name);
  ObjectDatabase db;
  db.parameters.voxel_m = GetFinite(in, "voxel");
  db.parameters.normal_radius_m = GetFinite(in, "normal radius");
  db.parameters.feature_radius_m = GetFinite(in, "feature radius");
  if (!(db.parameters.voxel_m > 0.0) || !(db.parameters.normal_radius_m > 0.0) ||
      !(db.parameters.feature_radius_m > 0.0)) {
    in.Fail("a radius or voxel size is not positive");
  }
  db.parameters.scanner = in.GetString("scanner", kMaxText);
  const std::size_t objects = in.GetCount("objects", 1);
  for (std::size_t i = 0; i < objects; ++i) db.objects.push_back(GetObject(in));
  if (!in.at_end()) in.Fail("unexpected bytes after the last object");
  if (db.objects.empty()) throw Error(name + ": holds no object");
  return db;
}

}  // namespace uwscan::perception
