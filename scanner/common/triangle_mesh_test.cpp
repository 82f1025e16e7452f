// LoadMesh's answers to files that are not meshes: each message names the file, the format it
// took it for and what is wrong.
#include "scanner/common/triangle_mesh.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

class LoadMeshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_triangle_mesh_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }
  // LoadMesh's message, "" when it did not throw.
  static std::string Refusal(const fs::path& path) {
    try {
      LoadMesh(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

void ExpectMentions(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

TEST_F(LoadMeshTest, APcdIsNamedAsAPointCloud) {
  const fs::path pcd = Write("scan.pcd",
                             "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                             "COUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\n"
                             "DATA ascii\n0 0 0\n");
  const std::string message = Refusal(pcd);
  ExpectMentions(message, pcd.string());
  ExpectMentions(message, "PCD");
  ExpectMentions(message, "point cloud, not a mesh");
  EXPECT_EQ(message.find("Invalid face index"), std::string::npos)
      << message;  // Assimp took it for OBJ
}

TEST_F(LoadMeshTest, APlyWithoutFacesIsNamedAsAPointCloud) {
  const fs::path ply =
      Write("scan.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  const std::string message = Refusal(ply);
  ExpectMentions(message, ply.string());
  ExpectMentions(message, "PLY with 3 vertices and no triangle");
}

TEST_F(LoadMeshTest, AnUnreadableObjNamesItsFormat) {
  const fs::path obj = Write("broken.obj", "v 0 0 0\nf 1 2 7\n");
  const std::string message = Refusal(obj);
  ExpectMentions(message, obj.string());
  ExpectMentions(message, "OBJ");
}

TEST_F(LoadMeshTest, ABrokenPlyOffOrStlNamesTheFormatItWasReadAs) {
  const std::pair<const char*, const char*> files[] = {
      {"cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n"},
      {"cut.off", "OFF\n3 1 0\n0 0 0\n"},
      {"cut.stl", "solid x\nfacet normal 0 0 1\n"},
  };
  for (const auto& [name, text] : files) {
    const fs::path path = Write(name, text);
    const std::string message = Refusal(path);
    ExpectMentions(message, path.string());
    const std::string extension = path.extension().string();
    std::string format;
    for (std::size_t i = 1; i < extension.size(); ++i)
      format += static_cast<char>(std::toupper(extension[i]));
    ExpectMentions(message, "read as " + format);
  }
}

// What is not a mesh file at all is named for what it is: missing, a directory, an extension
// that names no mesh format, a file with no vertex, a binary STL cut short behind a header that
// starts like an ASCII one.
TEST_F(LoadMeshTest, WhatIsNoMeshFileIsNamedForWhatItIs) {
  ExpectMentions(Refusal(dir_ / "missing.obj"), "no such file");
  fs::create_directories(dir_ / "folder.ply");
  ExpectMentions(Refusal(dir_ / "folder.ply"), "a directory, not a file");
  const std::string text = Refusal(Write("notes.txt", "ply\n"));
  ExpectMentions(text, "extension .txt names no mesh format");
  ExpectMentions(Refusal(Write("scan.las", "LASF")), "convert it to PLY, PCD or XYZ");
  ExpectMentions(Refusal(Write("garbage.obj", "this is no mesh\n")),
                 "OBJ with no vertex: not a mesh in that format");
  std::string stl = "solid exported by a tool that writes binary";
  stl.resize(80, ' ');
  const std::uint32_t claimed = 10;
  stl.append(reinterpret_cast<const char*>(&claimed), 4);  // little-endian here
  const float one = 1.0f;
  for (int value = 0; value < 3 * 12; ++value)  // 3 of the 10 triangles: normal, 3 corners
    stl.append(reinterpret_cast<const char*>(&one), 4);
  const fs::path cut = Write("cut_binary.stl", stl);
  const std::string message = Refusal(cut);
  ExpectMentions(message, "(read as STL): binary (not text)");
  ExpectMentions(message, "claims 10 triangles");
  ExpectMentions(message, "the file has 228");
}

TEST_F(LoadMeshTest, AMeshWrittenReadsBack) {
  const TriangleMesh box = sim::MakeBox({0.1, 0.2, 0.3});
  const fs::path ply = dir_ / "box.ply";
  WriteMeshPly(box, ply);
  const TriangleMesh read = LoadMesh(ply);
  EXPECT_EQ(read.triangles.size(), box.triangles.size());
  EXPECT_EQ(read.vertices.size(), box.vertices.size());
}

}  // namespace
}  // namespace uwscan::scanner
