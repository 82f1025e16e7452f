#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace uwscan::scanner::calibration {

// What the calibration steps consume: measurements extracted from a dataset's images (pattern
// corners, laser stripe peaks, laser dots), independent of how they were extracted, so that
// every step can be tested on exact synthetic observations and run on detected ones alike.

// A planar calibration pattern: chessboard (inner corners) or ChArUco board. Its frame {O}
// has the board in its x-y plane, z_O out of the board's back (OpenCV's convention), origin at
// the first inner corner (chessboard) or the board's corner (ChArUco).
enum class PatternType { kChessboard, kCharuco };
struct PatternSpec {
  PatternType type = PatternType::kChessboard;
  int columns = 9;          // inner corners along x_O (chessboard); squares along x (ChArUco)
  int rows = 6;             // inner corners along y_O (chessboard); squares along y (ChArUco)
  double square_m = 0.03;   // square edge, metres
  double marker_m = 0.022;  // ChArUco marker edge, metres
  std::string dictionary = "DICT_4X4_50";  // ChArUco ArUco dictionary (OpenCV name)

  void Check() const;  // throws uwscan::Error naming the field
  // Every corner the detector can report, in {O}, indexed by corner id.
  std::vector<Eigen::Vector3d> CornerPoints_O() const;
};

// One image of the pattern: the corners found (sub-pixel) and which corner ids they are.
struct PatternObservation {
  std::string image;  // file the corners came from (for messages), may be empty
  std::vector<int> corner_ids;
  std::vector<Eigen::Vector2d> corners_px;
};

// Laser stripe on a projection plane at one mirror command (galvanometer step).
struct StripeObservation {
  std::string image;
  int mirror_step = 0;
  std::vector<Eigen::Vector2d> peaks_px;
};

// Laser dot of the MEMS scanner for one voltage pair on one plane.
struct DotObservation {
  std::string image;
  Eigen::Vector2d volts = Eigen::Vector2d::Zero();
  Eigen::Vector2d dot_px = Eigen::Vector2d::Zero();
};

// A projection plane (the pattern board held at one pose) with what was projected onto it.
struct PlaneObservations {
  PatternObservation pattern;              // fixes the plane's pose (PnP)
  std::vector<StripeObservation> stripes;  // galvanometer steps 3 and 4
  std::vector<DotObservation> dots;        // MEMS step 5
};

}  // namespace uwscan::scanner::calibration
