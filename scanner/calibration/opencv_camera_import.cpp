#include "scanner/calibration/opencv_camera_import.hpp"

#include <array>
#include <sstream>
#include <string>

#include "scanner/calibration/opencv_storage_reader.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::scanner::calibration {
namespace {

// OpenCV's names of distortion coefficients 5 to 13, the ones PinholeCamera has not.
constexpr std::array<const char*, 9> kUnsupportedTerms = {"k4", "k5", "k6",    "s1",   "s2",
                                                          "s3", "s4", "tau_x", "tau_y"};

void SetCameraMatrix(const OpenCvMatrix& K, PinholeCamera& camera, const std::string& source) {
  if (K.rows != 3 || K.cols != 3) {
    throw Error(source + ": node 'camera_matrix' must be 3x3, got " + std::to_string(K.rows) + "x" +
                std::to_string(K.cols));
  }
  const auto at = [&K](int row, int col) { return K.values[3 * row + col]; };
  if (at(0, 1) != 0.0 || at(1, 0) != 0.0 || at(2, 0) != 0.0 || at(2, 1) != 0.0 || at(2, 2) != 1.0) {
    throw Error(source + ": node 'camera_matrix' must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  camera.fx_px = at(0, 0);
  camera.fy_px = at(1, 1);
  camera.cx_px = at(0, 2);
  camera.cy_px = at(1, 2);
}

void SetDistortion(const OpenCvMatrix& D, PinholeCamera& camera, const std::string& source) {
  const int n = static_cast<int>(D.values.size());
  if ((D.rows != 1 && D.cols != 1) || (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
    throw Error(source +
                ": node 'distortion_coefficients' must be a vector of 4, 5, 8, 12 or 14 values, "
                "got " +
                std::to_string(D.rows) + "x" + std::to_string(D.cols));
  }
  for (int k = 5; k < n; ++k) {
    if (D.values[k] != 0.0) {
      std::ostringstream message;
      message << source << ": node 'distortion_coefficients': " << kUnsupportedTerms[k - 5] << " = "
              << D.values[k] << " is non-zero; only OpenCV's standard model k1 k2 p1 p2 "
              << "k3 is supported (not the rational, thin-prism or tilted models): recalibrate "
              << "without CALIB_RATIONAL_MODEL, CALIB_THIN_PRISM_MODEL or CALIB_TILTED_MODEL";
      throw Error(message.str());
    }
  }
  camera.k1 = D.values[0];
  camera.k2 = D.values[1];
  camera.p1 = D.values[2];
  camera.p2 = D.values[3];
  camera.k3 = n >= 5 ? D.values[4] : 0.0;
}

}  // namespace

PinholeCamera ImportOpenCvCalibration(const std::filesystem::path& yaml) {
  const OpenCvStorage storage = OpenCvStorage::Read(yaml);
  const std::string source = QuotedPath(yaml);
  PinholeCamera camera;
  camera.width_px = storage.Integer("image_width");
  camera.height_px = storage.Integer("image_height");
  SetCameraMatrix(storage.Matrix("camera_matrix"), camera, source);
  SetDistortion(storage.Matrix("distortion_coefficients"), camera, source);
  try {
    camera.Check();
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
  return camera;
}

}  // namespace uwscan::scanner::calibration
