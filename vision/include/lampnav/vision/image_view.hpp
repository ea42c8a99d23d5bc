#pragma once
// A view of a camera frame as a driver hands it over: grey or colour, 8 or 16 bits per sample.
// The vision stages take this small value type, so that no public header needs OpenCV.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "lampnav/core/error.hpp"
#include "lampnav/core/image.hpp"

namespace lampnav::vision {

struct ImageView {
  const std::uint8_t* data = nullptr;
  int width = 0, height = 0;
  int channels = 1;          // 1 grey, 3 BGR, 4 BGRA (OpenCV's order)
  int bytes_per_sample = 1;  // 1, or 2 for 16-bit samples in the machine's byte order
  std::size_t stride = 0;    // bytes from one row to the next; 0 means rows are packed

  static ImageView of(const Image8& image) {
    return {image.pixels.data(),
            image.width,
            image.height,
            1,
            1,
            static_cast<std::size_t>(image.width)};
  }
  std::size_t row_bytes() const {
    return static_cast<std::size_t>(width) * channels * bytes_per_sample;
  }
  std::size_t row_stride() const { return stride != 0 ? stride : row_bytes(); }
};

// A rectangle of pixels, corners inclusive (u across, v down).
struct PixelBox {
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;
  bool empty() const { return u1 < u0 || v1 < v0; }
  bool contains(int u, int v) const { return u >= u0 && u <= u1 && v >= v0 && v <= v1; }
  bool overlaps(const PixelBox& b) const {
    return !empty() && !b.empty() && u0 <= b.u1 && b.u0 <= u1 && v0 <= b.v1 && b.v0 <= v1;
  }
  long area() const { return empty() ? 0 : static_cast<long>(u1 - u0 + 1) * (v1 - v0 + 1); }
};

// Checks a frame against the camera's size and the supported layouts; throws InputError at
// `where` (the caller names the source: a log and its message, an image file) saying what is wrong.
void check_image(const ImageView& image, int expected_width, int expected_height,
                 const ErrorContext& where);

// An 8-bit grey view of any supported frame: the frame itself when it is already 8-bit grey and
// packed, otherwise the luminance (ITU-R BT.601, as paper 2's Y) written into `scratch`.
ImageView grey_view(const ImageView& image, std::vector<std::uint8_t>& scratch);

}  // namespace lampnav::vision
