#include "lampnav/vision/image_view.hpp"

#include <algorithm>
#include <cstring>
#include <string>

namespace lampnav::vision {

void check_image(const ImageView& image, int expected_width, int expected_height,
                 const ErrorContext& where) {
  auto fail = [&](const std::string& message) { throw InputError(where, message); };
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) fail("the image is empty");
  if (image.channels != 1 && image.channels != 3 && image.channels != 4) {
    fail("the image has " + std::to_string(image.channels) +
         " channels; grey (1), BGR (3) or BGRA (4) are supported");
  }
  if (image.bytes_per_sample != 1 && image.bytes_per_sample != 2) {
    fail("the image has " + std::to_string(8 * image.bytes_per_sample) +
         "-bit samples; 8 or 16 bits are supported");
  }
  if (image.stride != 0 && image.stride < image.row_bytes()) {
    fail("the row stride (" + std::to_string(image.stride) + " bytes) is shorter than a row (" +
         std::to_string(image.row_bytes()) + " bytes)");
  }
  if (image.width != expected_width || image.height != expected_height) {
    fail("the image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
         " but the camera is " + std::to_string(expected_width) + "x" +
         std::to_string(expected_height));
  }
}

ImageView grey_view(const ImageView& image, std::vector<std::uint8_t>& scratch) {
  if (image.channels == 1 && image.bytes_per_sample == 1 &&
      image.row_stride() == static_cast<std::size_t>(image.width)) {
    return image;
  }
  const int w = image.width, h = image.height;
  scratch.resize(static_cast<std::size_t>(w) * h);
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* row = image.data + static_cast<std::size_t>(v) * image.row_stride();
    std::uint8_t* out = scratch.data() + static_cast<std::size_t>(v) * w;
    if (image.bytes_per_sample == 1) {
      if (image.channels == 1) {
        std::memcpy(out, row, static_cast<std::size_t>(w));
        continue;
      }
      for (int u = 0; u < w; ++u) {
        const std::uint8_t* p = row + static_cast<std::size_t>(u) * image.channels;
        // Integer BT.601 luminance from B, G, R: (29 B + 150 G + 77 R) / 256.
        out[u] = static_cast<std::uint8_t>((29 * p[0] + 150 * p[1] + 77 * p[2] + 128) >> 8);
      }
      continue;
    }
    for (int u = 0; u < w; ++u) {
      auto sample = [&](int c) {
        std::uint16_t s;
        std::memcpy(&s, row + (static_cast<std::size_t>(u) * image.channels + c) * 2, 2);
        return static_cast<std::uint32_t>(s);
      };
      const std::uint32_t y = image.channels == 1
                                  ? sample(0)
                                  : (29 * sample(0) + 150 * sample(1) + 77 * sample(2)) >> 8;
      out[u] = static_cast<std::uint8_t>(std::min<std::uint32_t>(255, (y + 128) >> 8));
    }
  }
  return ImageView{scratch.data(), w, h, 1, 1, static_cast<std::size_t>(w)};
}

}  // namespace lampnav::vision
