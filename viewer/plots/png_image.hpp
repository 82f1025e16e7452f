#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "viewer/scene/colour_map.hpp"

namespace uwscan::viewer {

// An 8-bit RGB picture, rows from the top, no padding.
struct RgbImage {
  int width_px = 0;
  int height_px = 0;
  std::vector<std::uint8_t> rgb;  // 3 * width * height

  Rgb At(int column, int row) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(row) * width_px + column);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Reads a PNG (grey, RGB or RGBA; alpha dropped) through VTK's reader. Throws uwscan::Error
// naming the file when it is missing or not a PNG.
RgbImage ReadPng(const std::filesystem::path& path);

// How two pictures of the same size differ.
struct ImageDifference {
  double mean_abs = 0.0;       // mean over every channel of every pixel, 0..255
  double fraction_over = 0.0;  // pixels with a channel differing by more than `threshold`
  int max_abs = 0;
};
// Throws uwscan::Error when the sizes differ.
ImageDifference CompareImages(const RgbImage& a, const RgbImage& b, int threshold);

}  // namespace uwscan::viewer
