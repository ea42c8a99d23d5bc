#pragma once
// The pixels of a sensor_msgs/msg/Image as one grey image, for every encoding a camera driver
// publishes that holds a picture (sensor_msgs/image_encodings.hpp): mono8 and mono16; rgb8,
// bgr8, rgba8, bgra8 and their 16-bit forms (8UC1, 8UC3, 8UC4, 16UC1, 16UC3 and 16UC4 read as
// OpenCV lays them out: mono, BGR, BGRA); packed YUV 4:2:2 (yuyv and uyvy, and their old names
// yuv422_yuy2 and yuv422), whose Y is the grey; and the four Bayer mosaics in 8 and 16 bits,
// demosaicked (as cv_bridge does) to grey. Colour becomes ITU-R 601 luma, rounded as OpenCV's
// colour conversion rounds it; 16-bit samples keep their high byte. Private to lampnav::io.

#include <cstdint>
#include <string>

#include "lampnav/core/image.hpp"

namespace lampnav::io::detail {

struct RawPixels {
  std::string encoding;
  bool big_endian = false;  // of 16-bit samples
  std::uint32_t width = 0, height = 0, step = 0;
  const std::string* data = nullptr;  // step x height bytes at least
};

// Throws CdrError naming the encoding, the size, the step or the data's length when they cannot
// be read.
Image8 grey_from_raw(const RawPixels& raw);

// The encodings grey_from_raw reads, for messages.
const char* raw_encodings_read();

}  // namespace lampnav::io::detail
