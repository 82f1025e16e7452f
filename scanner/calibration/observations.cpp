#include "scanner/calibration/observations.hpp"

#include <cmath>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {

void PatternSpec::Check() const {
  const OptionChecks check("PatternSpec");
  check.AtLeast("columns", columns, 2);
  check.AtLeast("rows", rows, 2);
  check.InRange("square_m", square_m, 0.0, 10.0, Interval::kOpen, "m");
  if (type == PatternType::kCharuco) {
    check.AtLeast("columns", columns, 3, "(a ChArUco board needs 3 squares a side)");
    check.AtLeast("rows", rows, 3, "(a ChArUco board needs 3 squares a side)");
    check.Require(marker_m > 0.0 && marker_m < square_m, "marker_m",
                  "in (0, square_m) = (0, " + OptionValueText(square_m) + ") m", marker_m);
    check.Require(dictionary.rfind("DICT_", 0) == 0, "dictionary",
                  "an OpenCV ArUco dictionary name (DICT_...)", OptionQuotedText(dictionary));
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
