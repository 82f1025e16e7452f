#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {

enum class PixelFormat : std::uint8_t { kMono8 = 0, kMono16 };

inline int BytesPerPixel(PixelFormat format) { return format == PixelFormat::kMono8 ? 1 : 2; }

// Largest value a pixel of `format` can hold: a pixel at this value may be saturated.
inline int MaxPixelValue(PixelFormat format) { return format == PixelFormat::kMono8 ? 255 : 65535; }

// A non-owning view of a single-channel camera frame: `height_px` rows of `width_px` pixels,
// row v starting `v * stride_bytes` bytes after `data`. Mono16 pixels are native-endian
// uint16_t and the data must be 2-byte aligned. Pixel coordinates follow OpenCV: the centre of
// the top-left pixel is (u, v) = (0, 0). The view never outlives the buffer it points into.
struct StripeImage {
  const void* data = nullptr;
  int width_px = 0;
  int height_px = 0;
  std::ptrdiff_t stride_bytes = 0;  // bytes from one row to the next, >= width * bytes/pixel
  PixelFormat format = PixelFormat::kMono8;

  static StripeImage Mono8(const std::uint8_t* pixels, int width_px, int height_px,
                           std::ptrdiff_t stride_bytes = 0) {
    return {pixels, width_px, height_px, stride_bytes > 0 ? stride_bytes : width_px,
            PixelFormat::kMono8};
  }
  static StripeImage Mono16(const std::uint16_t* pixels, int width_px, int height_px,
                            std::ptrdiff_t stride_bytes = 0) {
    return {pixels, width_px, height_px, stride_bytes > 0 ? stride_bytes : 2 * width_px,
            PixelFormat::kMono16};
  }

  bool empty() const { return data == nullptr || width_px <= 0 || height_px <= 0; }

  template <typename Pixel>
  const Pixel* Row(int v) const {
    return reinterpret_cast<const Pixel*>(static_cast<const std::byte*>(data) + v * stride_bytes);
  }

  // Pixel value at integer (u, v), whatever the format. For tests and slow paths only.
  int At(int u, int v) const {
    return format == PixelFormat::kMono8 ? Row<std::uint8_t>(v)[u] : Row<std::uint16_t>(v)[u];
  }

  // Throws uwscan::Error when the view is empty or its stride is too small for its width.
  void Check() const {
    if (data == nullptr) throw Error("stripe image: no pixel data (null pointer)");
    if (width_px <= 0 || height_px <= 0) {
      throw Error("stripe image: size " + std::to_string(width_px) + "x" +
                  std::to_string(height_px) + " px, expected at least 1x1");
    }
    if (stride_bytes < static_cast<std::ptrdiff_t>(width_px) * BytesPerPixel(format)) {
      throw Error("stripe image: stride_bytes " + std::to_string(stride_bytes) +
                  " smaller than one row of " + std::to_string(width_px) + " pixels");
    }
    if (format == PixelFormat::kMono16 &&
        (reinterpret_cast<std::uintptr_t>(data) % 2 != 0 || stride_bytes % 2 != 0)) {
      throw Error("stripe image: Mono16 data and stride_bytes must be 2-byte aligned");
    }
  }
};

}  // namespace uwscan::scanner
