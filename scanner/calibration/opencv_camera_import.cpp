#include "scanner/calibration/opencv_camera_import.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <system_error>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::scanner::calibration {
namespace {

// OpenCV's names of distortion coefficients 5 to 13, the ones PinholeCamera has not.
constexpr std::array<const char*, 9> kUnsupportedTerms = {"k4", "k5", "k6",    "s1",   "s2",
                                                          "s3", "s4", "tau_x", "tau_y"};

class Reader {
 public:
  explicit Reader(const std::filesystem::path& path) : file_(path.string()) {}

  [[noreturn]] void Fail(const std::string& what) const { throw Error(file_ + ": " + what); }

  cv::FileNode Node(const cv::FileStorage& storage, const char* name) const {
    cv::FileNode node;
    try {
      node = storage[name];
    } catch (const cv::Exception&) {  // OpenCV asserts when the top level is not a map
      Fail(std::string("missing node '") + name + "' (the file's top level is not a map of nodes)");
    }
    if (node.empty()) Fail(std::string("missing node '") + name + "'");
    return node;
  }

  int Int(const cv::FileStorage& storage, const char* name) const {
    const cv::FileNode node = Node(storage, name);
    if (!node.isInt()) Fail(std::string("node '") + name + "' must be an integer");
    return static_cast<int>(node);
  }

  cv::Mat Matrix(const cv::FileStorage& storage, const char* name) const {
    const cv::FileNode node = Node(storage, name);
    cv::Mat matrix;
    try {
      if (node.isMap()) node >> matrix;
    } catch (const cv::Exception&) {
      matrix.release();
    }
    if (matrix.empty() || matrix.channels() != 1) {
      Fail(std::string("node '") + name + "' must be an OpenCV matrix (!!opencv-matrix)");
    }
    matrix.convertTo(matrix, CV_64F);
    return matrix;
  }

 private:
  std::string file_;
};

// OpenCV's FileStorage trusts a matrix's `rows` and `cols` and its text: a damaged byte there
// made it allocate gigabytes (found by tests/fuzz). An intrinsics file is a few hundred bytes of
// ASCII with matrices of at most 1x14: anything else is refused before OpenCV parses it.
void CheckBeforeOpenCv(const std::filesystem::path& yaml, const Reader& reader) {
  constexpr std::uintmax_t kMaxBytes = 1 << 20;
  std::error_code error;
  if (std::filesystem::file_size(yaml, error) > kMaxBytes) reader.Fail("larger than 1 MiB: not a calibration file");
  const std::string text = ReadFileBytes(yaml);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && c != '\n' && c != '\r' && c != '\t') || c > 0x7e) {
      reader.Fail("byte " + std::to_string(c) + " at offset " + std::to_string(i) +
                  " is not ASCII text (an OpenCV calibration YAML is)");
    }
  }
  // Any line that speaks of rows or cols must be exactly "rows: N" or "cols: N" (YAML) or
  // "<rows>N</rows>" or "<cols>N</cols>" (XML), 1 <= N <= 16.
  static const std::regex size_line(
      R"(^\s*(?:(rows|cols)\s*:\s*([0-9]{1,2})|<(rows|cols)>\s*([0-9]{1,2})\s*</(rows|cols)>)\s*\r?$)");
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (line.find("rows") == std::string::npos && line.find("cols") == std::string::npos) continue;
    std::smatch match;
    const bool matched = std::regex_match(line, match, size_line);
    const int size = matched ? std::stoi(match[2].matched ? match[2].str() : match[4].str()) : 0;
    if (size < 1 || size > 16) {
      reader.Fail("line " + std::to_string(number) + ": expected a matrix size 'rows: N' or 'cols: N' (XML <rows>N</rows>) with N from 1 to 16");
    }
  }
}

PinholeCamera ReadOpenCvCalibration(const std::filesystem::path& yaml) {
  const Reader reader(yaml);
  std::error_code error;
  if (!std::filesystem::is_regular_file(yaml, error)) {
    reader.Fail("no such file (expected an OpenCV calibration YAML)");
  }
  CheckBeforeOpenCv(yaml, reader);
  cv::FileStorage storage;
  try {
    if (!storage.open(yaml.string(), cv::FileStorage::READ)) {
      reader.Fail("cannot be opened as an OpenCV FileStorage (YAML or XML)");
    }
  } catch (const cv::Exception& e) {
    reader.Fail(std::string("not a readable OpenCV FileStorage file: ") + e.what());
  }

  PinholeCamera camera;
  camera.width_px = reader.Int(storage, "image_width");
  camera.height_px = reader.Int(storage, "image_height");

  const cv::Mat K = reader.Matrix(storage, "camera_matrix");
  if (K.rows != 3 || K.cols != 3) {
    reader.Fail("node 'camera_matrix' must be 3x3, got " + std::to_string(K.rows) + "x" +
                std::to_string(K.cols));
  }
  if (K.at<double>(0, 1) != 0.0 || K.at<double>(1, 0) != 0.0 || K.at<double>(2, 0) != 0.0 ||
      K.at<double>(2, 1) != 0.0 || K.at<double>(2, 2) != 1.0) {
    reader.Fail("node 'camera_matrix' must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  camera.fx_px = K.at<double>(0, 0);
  camera.fy_px = K.at<double>(1, 1);
  camera.cx_px = K.at<double>(0, 2);
  camera.cy_px = K.at<double>(1, 2);

  const cv::Mat D = reader.Matrix(storage, "distortion_coefficients");
  const int n = static_cast<int>(D.total());
  if ((D.rows != 1 && D.cols != 1) || (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
    reader.Fail(
        "node 'distortion_coefficients' must be a vector of 4, 5, 8, 12 or 14 values, "
        "got " +
        std::to_string(D.rows) + "x" + std::to_string(D.cols));
  }
  const auto at = [&D](int k) { return D.at<double>(k); };
  for (int k = 5; k < n; ++k) {
    if (at(k) != 0.0) {
      std::ostringstream message;
      message << "node 'distortion_coefficients': " << kUnsupportedTerms[k - 5] << " = " << at(k)
              << " is non-zero; only OpenCV's standard model k1 k2 p1 p2 k3 is "
              << "supported (not the rational, thin-prism or tilted models): recalibrate "
              << "without CALIB_RATIONAL_MODEL, CALIB_THIN_PRISM_MODEL or CALIB_TILTED_MODEL";
      reader.Fail(message.str());
    }
  }
  camera.k1 = at(0);
  camera.k2 = at(1);
  camera.p1 = at(2);
  camera.p2 = at(3);
  camera.k3 = n >= 5 ? at(4) : 0.0;
  try {
    camera.Check();
  } catch (const Error& e) {
    reader.Fail(e.what());
  }
  return camera;
}

}  // namespace

PinholeCamera ImportOpenCvCalibration(const std::filesystem::path& yaml) {
  // OpenCV's parser throws more than cv::Exception on damaged text (std::length_error, found by
  // tests/fuzz): whatever it throws is a refusal of the file.
  try {
    return ReadOpenCvCalibration(yaml);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(yaml.string() + ": not a readable OpenCV calibration file (" + e.what() + ")");
  }
}

}  // namespace uwscan::scanner::calibration
