#pragma once
// Fixtures the recognition tests share: the virtual scanner they scan with, small object
// databases, and objects scanned lying on a seabed.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "scanner/common/test_cache.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::perception::recognition_test {

namespace sim = scanner::sim;

// A folder of this test process's own for the files the tests write (two test programs, or the
// same one built twice, may run at once), removed when the process ends.
struct OwnTestDir {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("uwscan_recognition_test_" + std::to_string(::getpid()));
  OwnTestDir() { std::filesystem::create_directories(path); }
  ~OwnTestDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};
inline std::filesystem::path TestDir() {
  static const OwnTestDir dir;
  return dir.path;
}

inline const sim::VirtualScanner& Scanner() {
  static const sim::VirtualScanner scanner = [] {
    sim::VirtualScannerOptions options;
    options.pattern.galvo.step_stride = 2;
    return sim::VirtualScanner(scanner::DefaultScanner(scanner::ScannerKind::kGalvo), options);
  }();
  return scanner;
}

inline ObjectDatabase Build(const std::vector<std::string>& names, int threads) {
  std::vector<ObjectSource> sources;
  for (const std::string& name : names) sources.push_back(CatalogueObject(name));
  DatabaseBuildOptions options;
  options.views = 16;
  options.threads = threads;
  return BuildObjectDatabase(sources, Scanner(), options);
}

// An exclusive lock on `path` (none for an empty path) until the end of its scope.
class FileLock {
 public:
  explicit FileLock(const std::string& path)
      : fd_(path.empty() ? -1 : ::open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);
  }
  ~FileLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

// Read back from its file, as `recognize` reads a database. Under CTest the file is built by the
// first test that needs it and shared by the others (scanner/common/test_cache.hpp).
inline const ObjectDatabase& PipeFlangeValveDb() {
  static const ObjectDatabase db = [] {
    const std::optional<std::filesystem::path> cache = ::uwscan::test::TestCacheFolder();
    const std::filesystem::path file =
        cache ? *cache / "pipe_flange_valve.db"
              : std::filesystem::temp_directory_path() /
                    ("uwscan_pipe_flange_valve_" + std::to_string(getpid()) + ".db");
    std::filesystem::create_directories(file.parent_path());
    {
      // Tests running side by side wait for the one building it instead of building it too.
      const FileLock lock(cache ? file.string() + ".lock" : std::string());
      if (!std::filesystem::exists(file)) Build({"pipe", "flange", "valve_wheel"}, 2).Save(file);
    }
    ObjectDatabase loaded = ObjectDatabase::Load(file);
    if (!cache) std::filesystem::remove(file);
    return loaded;
  }();
  return db;
}

inline sim::SceneObject Placed(const scanner::TriangleMesh& mesh, const Eigen::Isometry3d& T_W_O) {
  sim::SceneObject o;
  o.name = "object";
  o.shape = sim::ObjectShape::kMesh;
  o.mesh = mesh;
  o.T_W_O = T_W_O;
  return o;
}

// A seabed (z = 0, up +z) and the object lying on it, its y_O up and z_O along y.
inline std::vector<sim::SceneObject> OnSeabed(const scanner::TriangleMesh& mesh) {
  sim::SceneObject seabed;
  seabed.name = "seabed";
  seabed.shape = sim::ObjectShape::kPlane;
  seabed.mesh = sim::MakeRectangle(4.0, 4.0);
  Eigen::Isometry3d T_W_O = Eigen::Isometry3d::Identity();
  T_W_O.linear() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  double lowest = 1e9;
  for (const Eigen::Vector3d& v : mesh.vertices)
    lowest = std::min(lowest, (T_W_O.linear() * v).z());
  T_W_O.translation() = Eigen::Vector3d(0.0, 0.0, -lowest);
  return {seabed, Placed(mesh, T_W_O)};
}

// That scene scanned from `eye`, looking at the object.
struct Scan {
  PointCloud cloud;
  Eigen::Isometry3d T_S_O;
};
inline Scan ScanOnSeabed(const scanner::TriangleMesh& mesh, const Eigen::Vector3d& eye,
                         std::uint64_t seed) {
  const std::vector<sim::SceneObject> scene = OnSeabed(mesh);
  const Eigen::Isometry3d T_W_O = scene[1].T_W_O;
  const Eigen::Isometry3d T_W_C = sim::LookAt(eye, T_W_O.translation(), Eigen::Vector3d::UnitZ());
  const sim::VirtualScan scan = Scanner().Scan(scene, T_W_C, seed);
  return {MakeCloud(scan.points_C), T_W_C.inverse() * T_W_O};
}

// The segment whose centroid lies nearest the object's true position.
inline const RecognizedObject* Nearest(const RecognitionResult& r, const Scan& scan) {
  const RecognizedObject* best = nullptr;
  for (const RecognizedObject& o : r.objects) {
    if (best == nullptr || (o.centroid_S - scan.T_S_O.translation()).norm() <
                               (best->centroid_S - scan.T_S_O.translation()).norm()) {
      best = &o;
    }
  }
  return best;
}

}  // namespace uwscan::perception::recognition_test
