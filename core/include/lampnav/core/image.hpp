#pragma once
// A small 8-bit grey image value type, so that public headers need no OpenCV.

#include <cstdint>
#include <vector>

namespace lampnav {

struct Image8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // row-major, width * height

  Image8() = default;
  Image8(int w, int h, std::uint8_t fill = 0)
      : width(w),
        height(h),
        pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}
  std::uint8_t& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  std::uint8_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
  bool empty() const { return pixels.empty(); }
};

}  // namespace lampnav
