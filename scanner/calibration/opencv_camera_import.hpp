#pragma once

#include <filesystem>

#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::scanner::calibration {

// Camera intrinsics from the YAML (or XML) file that OpenCV's calibration sample writes with
// cv::FileStorage: image_width, image_height, camera_matrix (3x3) and distortion_coefficients
// (4, 5, 8, 12 or 14 values: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tau_x tau_y]]]]).
// Only OpenCV's standard model k1 k2 p1 p2 k3 is supported: a file whose rational (k4..k6),
// thin-prism (s1..s4) or tilt (tau_x, tau_y) terms are non-zero is refused, as is a camera
// matrix with skew, rather than silently dropping terms. Other nodes (the sample's
// calibration_time, flags, per-view errors, extrinsics) are ignored. The file is read without
// OpenCV (see OpenCvStorage), so a damaged file is refused rather than hanging the process.
// Throws uwscan::Error naming the file and, where one is at fault, the node: missing or
// unreadable file, malformed YAML, missing node, wrong type or size, unsupported terms, or
// intrinsics that PinholeCamera::Check refuses.
PinholeCamera ImportOpenCvCalibration(const std::filesystem::path& yaml);

}  // namespace uwscan::scanner::calibration
