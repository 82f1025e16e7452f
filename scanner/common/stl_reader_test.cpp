// uwscan's STL reader against Assimp's importer (the independent reference) on binary and
// ASCII files of a known box, and its refusals of broken files.
#include "scanner/common/stl_reader.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <assimp/Importer.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

class StlReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_stl_reader_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    box_ = sim::MakeBox({0.1, 0.2, 0.3});
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The box as binary STL, its 80-byte header starting with "solid" as many exporters write it.
  fs::path WriteBinary() const {
    std::string bytes = "solid box, written as binary";
    bytes.resize(80, ' ');
    const std::uint32_t count = static_cast<std::uint32_t>(box_.triangles.size());
    bytes.append(reinterpret_cast<const char*>(&count), 4);  // the test machines are little-endian
    for (const Eigen::Vector3i& t : box_.triangles) {
      const float normal[3] = {0.0f, 0.0f, 0.0f};
      bytes.append(reinterpret_cast<const char*>(normal), 12);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f v = box_.vertices[std::size_t(t[k])].cast<float>();
        bytes.append(reinterpret_cast<const char*>(v.data()), 12);
      }
      bytes.append(2, '\0');
    }
    const fs::path path = dir_ / "box_binary.stl";
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  fs::path WriteAscii(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  std::string AsciiBox() const {
    std::ostringstream out;
    out.precision(9);
    out << "solid vertex box\n";  // a name that is also a keyword
    for (const Eigen::Vector3i& t : box_.triangles) {
      out << "  facet normal 0 0 0\n    outer loop\n";
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f v = box_.vertices[std::size_t(t[k])].cast<float>();
        out << "      vertex " << v.x() << " " << v.y() << " " << v.z() << "\n";
      }
      out << "    endloop\n  endfacet\n";
    }
    out << "endsolid vertex box\n";
    return out.str();
  }

  // What Assimp makes of the file, its triangles and merged vertices (the box has no degenerate
  // triangle, so the options that drop them do not matter here).
  static TriangleMesh ByAssimp(const fs::path& path) {
    Assimp::Importer importer;
    const aiScene* scene =
        importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    EXPECT_NE(scene, nullptr) << importer.GetErrorString();
    TriangleMesh mesh;
    if (scene == nullptr) return mesh;
    const aiMesh* part = scene->mMeshes[0];
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      mesh.vertices.emplace_back(part->mVertices[v].x, part->mVertices[v].y, part->mVertices[v].z);
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      mesh.triangles.emplace_back(int(face.mIndices[0]), int(face.mIndices[1]),
                                  int(face.mIndices[2]));
    }
    return mesh;
  }

  // Same triangles, corner by corner, by position.
  static void ExpectSameTriangles(const TriangleMesh& a, const TriangleMesh& b) {
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    for (std::size_t t = 0; t < a.triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.vertices[std::size_t(a.triangles[t][k])],
                  b.vertices[std::size_t(b.triangles[t][k])])
            << "triangle " << t << " corner " << k;
      }
    }
  }

  std::string ErrorOf(const fs::path& path) const {
    try {
      ReadStl(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }

  fs::path dir_;
  TriangleMesh box_;
};

TEST_F(StlReaderTest, BinaryAndAsciiGiveAssimpsTrianglesWithSharedVertices) {
  for (const fs::path& path : {WriteBinary(), WriteAscii("box_ascii.stl", AsciiBox())}) {
    SCOPED_TRACE(path.filename().string());
    const TriangleMesh mesh = ReadStl(path);
    EXPECT_EQ(mesh.vertices.size(), 8u);  // the box's corners, each once
    EXPECT_EQ(mesh.triangles.size(), 12u);
    ExpectSameTriangles(mesh, ByAssimp(path));
    EXPECT_NEAR(mesh.BoundingBoxDiagonal(), box_.BoundingBoxDiagonal(), 1e-7);
  }
}

TEST_F(StlReaderTest, LoopsOfMoreCornersAreFannedAndDegenerateTrianglesDropped) {
  const TriangleMesh mesh =
      ReadStl(WriteAscii("quad.stl",
                         "solid quad\n facet normal 0 0 1\n  outer loop\n"
                         "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex +0 1e0 0\n"
                         "  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n"
                         "   vertex 0 0 0\n   vertex 0 0 0\n   vertex 1 1 0\n"
                         "  endloop\n endfacet\nendsolid quad\n"));
  EXPECT_EQ(mesh.vertices.size(), 4u);
  ASSERT_EQ(mesh.triangles.size(),
            2u);  // the quad in two; the triangle with a repeated corner gone
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));

  // Two solids in one file make one mesh; their shared corner is one vertex.
  const TriangleMesh two =
      ReadStl(WriteAscii("two_solids.stl",
                         "solid a\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                         "endloop\nendsolid a\nsolid b\nouter loop\nvertex 0 0 0\n"
                         "vertex 0 0 1\nvertex 0 1 0\nendloop\nendsolid b\n"));
  EXPECT_EQ(two.triangles.size(), 2u);
  EXPECT_EQ(two.vertices.size(), 4u);
}

TEST_F(StlReaderTest, BrokenFilesNameTheFileAndWhatIsWrong) {
  std::string ascii = AsciiBox();
  EXPECT_NE(ErrorOf(WriteAscii("cut.stl", ascii.substr(0, ascii.size() / 2))).find("cut short"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf(WriteAscii("two.stl",
                         "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                         "endloop\nendfacet\nendsolid s\n"))
          .find("line 6: a loop of fewer than 3 vertices"),
      std::string::npos);
  EXPECT_NE(ErrorOf(WriteAscii("nan.stl", "solid s\nouter loop\nvertex 0 zero 0\n"))
                .find("line 3: expected a vertex"),
            std::string::npos);
  EXPECT_NE(ErrorOf(WriteAscii("junk.stl", std::string(200, '\x7f'))).find("neither binary STL"),
            std::string::npos);
  // A binary file one byte short of its count is read as ASCII (its header says "solid") and
  // refused.
  std::ifstream in(WriteBinary(), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(ErrorOf(WriteAscii("short.stl", bytes.substr(0, bytes.size() - 1))).find("short.stl"),
            std::string::npos);
  EXPECT_NE(ErrorOf(dir_ / "missing.stl").find("missing.stl"), std::string::npos);
}

}  // namespace
}  // namespace uwscan::scanner
