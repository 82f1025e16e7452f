#pragma once

#include <filesystem>
#include <optional>

#include "scanner/calibration/observations.hpp"

namespace uwscan::scanner::calibration {

// Finds the calibration pattern in an image file: the corners (sub-pixel, OpenCV's pixel
// convention: the centre of the top-left pixel is (0, 0)) and their ids, which index
// PatternSpec::CornerPoints_O().
//
// Image: anything cv::imread reads; colour is converted to grey and 16-bit images (Mono16,
// often 10 or 12 significant bits) are stretched linearly from their minimum to their maximum
// onto 8 bits for detection, while a chessboard's corners are refined on the full-depth image.
//
// Chessboard (spec.columns x spec.rows inner corners): cv::findChessboardCorners, then
// cv::cornerSubPix with a window of 0.4 times the smallest spacing of neighbouring corners
// (so the window never reaches the next corner), 3 to 25 px half-size. Ids are OpenCV's order,
// row by row. Unambiguous only for boards with one odd and one even count (e.g. 9 x 6): a board
// with both counts even or both odd looks the same turned by 180 degrees, and OpenCV then
// numbers it from whichever end it likes, view by view (the pose of {O} flips with it).
//
// ChArUco (spec.columns x spec.rows squares, OpenCV 4.6 contrib board layout, marker ids from
// 0): cv::aruco::detectMarkers, refineDetectedMarkers against the board, then
// interpolateCornersCharuco (local homographies, sub-pixel refinement). Corners in id order.
//
// Returns std::nullopt when no pattern is found (for ChArUco: fewer than 4 corners, which fix
// no pose). Throws uwscan::Error naming the file when it cannot be read as an image or has an
// unsupported pixel format, and on an invalid spec.
std::optional<PatternObservation> DetectPattern(const std::filesystem::path& image,
                                                const PatternSpec& spec);

}  // namespace uwscan::scanner::calibration
