#include "viewer/plots/png_image.hpp"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <algorithm>
#include <cstdlib>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {

RgbImage ReadPng(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path.string() + ": no such file");
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw Error(path.string() + ": not a PNG file");
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  const int channels = data->GetNumberOfScalarComponents();
  if (data->GetScalarType() != VTK_UNSIGNED_CHAR || dims[0] <= 0 || dims[1] <= 0 || channels < 1) {
    throw Error(path.string() + ": not an 8-bit PNG");
  }
  RgbImage image;
  image.width_px = dims[0];
  image.height_px = dims[1];
  image.rgb.resize(3 * static_cast<std::size_t>(dims[0]) * dims[1]);
  const auto* in = static_cast<const unsigned char*>(data->GetScalarPointer());
  for (int row = 0; row < dims[1]; ++row) {
    // VTK's images start at the bottom row.
    const unsigned char* src =
        in + static_cast<std::size_t>(dims[1] - 1 - row) * dims[0] * channels;
    std::uint8_t* dst = image.rgb.data() + static_cast<std::size_t>(row) * dims[0] * 3;
    for (int x = 0; x < dims[0]; ++x) {
      for (int c = 0; c < 3; ++c) dst[3 * x + c] = src[x * channels + (channels >= 3 ? c : 0)];
    }
  }
  return image;
}

ImageDifference CompareImages(const RgbImage& a, const RgbImage& b, int threshold) {
  if (a.width_px != b.width_px || a.height_px != b.height_px) {
    throw Error("images differ in size: " + std::to_string(a.width_px) + "x" +
                std::to_string(a.height_px) + " and " + std::to_string(b.width_px) + "x" +
                std::to_string(b.height_px));
  }
  ImageDifference d;
  std::size_t over = 0;
  double sum = 0.0;
  for (std::size_t p = 0; p < a.rgb.size(); p += 3) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      const int diff = std::abs(int{a.rgb[p + c]} - int{b.rgb[p + c]});
      sum += diff;
      worst = std::max(worst, diff);
    }
    d.max_abs = std::max(d.max_abs, worst);
    if (worst > threshold) ++over;
  }
  const std::size_t pixels = a.rgb.size() / 3;
  d.mean_abs = pixels ? sum / static_cast<double>(a.rgb.size()) : 0.0;
  d.fraction_over = pixels ? static_cast<double>(over) / static_cast<double>(pixels) : 0.0;
  return d;
}

}  // namespace uwscan::viewer
