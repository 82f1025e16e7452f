#include "scanner/calibration/observations.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {

void PatternSpec::Check() const {
  if (columns < 2 || rows < 2) throw Error("pattern: columns and rows must be >= 2");
  if (!(square_m > 0.0 && square_m < 10.0)) throw Error("pattern: square_m must be in (0, 10) m");
  if (type == PatternType::kCharuco) {
    if (columns < 3 || rows < 3) throw Error("pattern: a ChArUco board needs >= 3 squares a side");
    if (!(marker_m > 0.0 && marker_m < square_m)) {
      throw Error("pattern: marker_m must be in (0, square_m)");
    }
    if (dictionary.rfind("DICT_", 0) != 0) {
      throw Error("pattern: dictionary '" + dictionary +
                  "' is not an OpenCV ArUco dictionary name");
    }
  }
}

std::vector<Eigen::Vector3d> PatternSpec::CornerPoints_O() const {
  Check();
  std::vector<Eigen::Vector3d> points;
  if (type == PatternType::kChessboard) {
    // OpenCV's order: row by row, x fastest; the first inner corner at the origin.
    for (int y = 0; y < rows; ++y) {
      for (int x = 0; x < columns; ++x) points.emplace_back(x * square_m, y * square_m, 0.0);
    }
  } else {
    // ChArUco corners are the inner corners of the squares grid, ids row by row.
    for (int y = 1; y < rows; ++y) {
      for (int x = 1; x < columns; ++x) points.emplace_back(x * square_m, y * square_m, 0.0);
    }
  }
  return points;
}

}  // namespace uwscan::scanner::calibration
