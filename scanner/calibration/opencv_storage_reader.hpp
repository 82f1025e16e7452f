#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace uwscan::scanner::calibration {

// A matrix as cv::FileStorage writes it (`!!opencv-matrix` in YAML, type_id="opencv-matrix"
// in XML): rows x cols values, row-major.
struct OpenCvMatrix {
  int rows = 0;
  int cols = 0;
  std::vector<double> values;
};

// A top-level node: a scalar's text, or a matrix's parts as written (checked only when the
// matrix is read, so that nodes nobody reads, such as the per-view ones of OpenCV's
// calibration sample, cannot make a file unreadable).
struct OpenCvNode {
  bool is_matrix = false;
  std::string scalar;
  std::string rows, cols, dt;
  std::vector<std::string> values;
  std::string malformed;  // what is wrong with the matrix's layout; empty when nothing is
};

// The top-level nodes of a file that OpenCV's cv::FileStorage wrote, in YAML or XML, read
// without OpenCV: its parser hung, threw and allocated gigabytes on damaged files (found by
// tests/fuzz), while yaml-cpp and libxml2 are bounded and well fuzzed. Scalars and matrices
// are kept, other nodes (lists, nested maps) skipped; a matrix read must be single-channel and
// at most 16 x 16 (a vector of 14 distortion coefficients is the largest a calibration needs).
// The file must be ASCII text and at most 1 MiB.
class OpenCvStorage {
 public:
  // Throws uwscan::Error naming the file: missing, too large, not text, malformed YAML or XML,
  // or a matrix whose rows, cols, dt or data disagree.
  static OpenCvStorage Read(const std::filesystem::path& path);

  // Throws uwscan::Error naming the file and the node: missing, or of another kind.
  int Integer(const std::string& name) const;
  OpenCvMatrix Matrix(const std::string& name) const;

 private:
  OpenCvStorage(std::string source, std::map<std::string, OpenCvNode> nodes)
      : source_(std::move(source)), nodes_(std::move(nodes)) {}

  [[noreturn]] void Fail(const std::string& what) const;
  const OpenCvNode& Find(const std::string& name) const;

  std::string source_;
  std::map<std::string, OpenCvNode> nodes_;
};

}  // namespace uwscan::scanner::calibration
