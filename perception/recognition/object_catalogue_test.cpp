// Objects from mesh files: their units and the sizes no object can have.
#include "perception/recognition/object_catalogue.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::perception {
namespace {

namespace fs = std::filesystem;

class MeshObjectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() / ("uwscan_object_catalogue_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // A 0.3 x 0.2 x 0.1 m box written in the given units per metre (1000: millimetres).
  fs::path Box(const std::string& name, double units_per_m) const {
    scanner::TriangleMesh box = scanner::sim::MakeBox({0.3, 0.2, 0.1});
    for (Eigen::Vector3d& v : box.vertices) v *= units_per_m;
    const fs::path path = dir_ / name;
    scanner::WriteMeshPly(box, path);
    return path;
  }
  static std::string Refusal(const fs::path& path, double units_to_m) {
    try {
      MeshObject(path, units_to_m);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(MeshObjectTest, AMeshInMillimetresWithItsUnitsIsTheMeshInMetres) {
  const ObjectSource metres = MeshObject(Box("box_m.ply", 1.0));
  const ObjectSource millimetres = MeshObject(Box("box_mm.ply", 1000.0), 0.001);
  ASSERT_EQ(metres.mesh.vertices.size(), millimetres.mesh.vertices.size());
  for (std::size_t i = 0; i < metres.mesh.vertices.size(); ++i)
    EXPECT_LT((metres.mesh.vertices[i] - millimetres.mesh.vertices[i]).norm(), 1e-6);
}

TEST_F(MeshObjectTest, AMeshInMillimetresTakenForMetresIsRefusedWithTheUnitsHint) {
  const fs::path mm = Box("box_mm.ply", 1000.0);
  const std::string message = Refusal(mm, 1.0);
  EXPECT_NE(message.find(mm.string()), std::string::npos) << message;
  EXPECT_NE(message.find("374.2 m across"), std::string::npos) << message;
  EXPECT_NE(message.find("--units mm"), std::string::npos) << message;
  // A mesh in metres said to be in millimetres is 0.37 mm across.
  EXPECT_NE(Refusal(Box("box_m.ply", 1.0), 0.001).find("--units m"), std::string::npos);
  EXPECT_THROW(MeshObject(Box("box.ply", 1.0), 0.0), Error);
}

// A name meant as a file that is not there is said to be missing, not taken for an unknown
// procedural object; a pipe is never opened (it would block for ever with no writer).
TEST_F(MeshObjectTest, WhatIsNotAFileIsNamedForWhatItIs) {
  const std::string missing = (dir_ / "valve.ply").string();
  const std::string message = [&] {
    try {
      CatalogueObject(missing);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(message.find(missing + "': no such file"), std::string::npos) << message;
  EXPECT_NE(message.find("elbow"), std::string::npos) << message;  // the procedural ones listed

  const fs::path fifo = dir_ / "scan.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_FALSE(IsCloudFile(fifo));
  EXPECT_NE(Refusal(fifo, 1.0).find("not a regular file"), std::string::npos);
  const fs::path folder = dir_ / "folder.ply";
  fs::create_directories(folder);
  EXPECT_NE(Refusal(folder, 1.0).find("a directory, not a file"), std::string::npos);
}

}  // namespace
}  // namespace uwscan::perception
