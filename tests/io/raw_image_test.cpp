// sensor_msgs/msg/Image in every encoding a camera driver publishes a picture in: grey as OpenCV
// itself makes it from the same colours (the other side's code), Y of packed YUV as it is, and
// Bayer mosaics of a known colour demosaicked to that colour's luma. Rows padded, 16-bit samples
// in both byte orders; what cannot be read is refused, naming the encoding or the size.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cdr.hpp"
#include "lampnav/io/ros2_messages.hpp"

namespace lampnav::io {
namespace {

using ::testing::HasSubstr;

struct Rgb {
  int r, g, b;
};

// A colour scene with every channel varying on its own.
Rgb scene(int x, int y) {
  return {(x * 7 + y * 3) % 256, (x * 2 + y * 11 + 40) % 256, (255 - x * 5 + y) & 255};
}

// A message whose pixels `put` writes: `bytes_per_pixel` a pixel, rows padded to `step`.
std::string message(const std::string& encoding, int w, int h, int bytes_per_pixel, int step,
                    bool big_endian, const std::function<void(int, int, unsigned char*)>& put) {
  std::string data(std::size_t(step) * h, '\x55');
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      put(x, y,
          reinterpret_cast<unsigned char*>(
              &data[std::size_t(y) * step + std::size_t(x) * bytes_per_pixel]));
  return CdrWriter(true)
      .header(1'000'000'000, "cam")
      .u32(static_cast<std::uint32_t>(h))
      .u32(static_cast<std::uint32_t>(w))
      .string(encoding)
      .u8(big_endian ? 1 : 0)
      .u32(static_cast<std::uint32_t>(step))
      .bytes(data)
      .data();
}

void put16(unsigned char* p, int v, bool big_endian) {
  p[big_endian ? 0 : 1] = static_cast<unsigned char>(v >> 8);
  p[big_endian ? 1 : 0] = static_cast<unsigned char>(v & 0xFF);
}

// A 16-bit sample of the scene's 8-bit value v: v in its high byte, its low byte another.
int wide(int v, int x, int y, int channel) {
  return v * 256 + (x * 37 + y * 11 + channel * 71) % 256;
}

// OpenCV's grey of the scene, from a BGR image of 8 or 16 bits; of 16 bits, the grey's high byte.
cv::Mat opencv_grey(int w, int h, bool sixteen) {
  cv::Mat bgr(h, w, sixteen ? CV_16UC3 : CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgb c = scene(x, y);
      if (sixteen)
        bgr.at<cv::Vec3w>(y, x) = cv::Vec3w(static_cast<std::uint16_t>(wide(c.b, x, y, 2)),
                                            static_cast<std::uint16_t>(wide(c.g, x, y, 1)),
                                            static_cast<std::uint16_t>(wide(c.r, x, y, 0)));
      else
        bgr.at<cv::Vec3b>(y, x) =
            cv::Vec3b(static_cast<std::uint8_t>(c.b), static_cast<std::uint8_t>(c.g),
                      static_cast<std::uint8_t>(c.r));
    }
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  if (!sixteen) return grey;
  cv::Mat high(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      high.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(grey.at<std::uint16_t>(y, x) >> 8);
  return high;
}

TEST(RawImage, ColourBecomesTheLumaOpenCvMakesOfIt) {
  const int w = 41, h = 23;
  struct Case {
    const char* encoding;
    int channels, depth;
    bool rgb;
  };
  for (const Case c :
       {Case{"rgb8", 3, 1, true}, Case{"bgr8", 3, 1, false}, Case{"8UC3", 3, 1, false},
        Case{"rgba8", 4, 1, true}, Case{"bgra8", 4, 1, false}, Case{"rgb16", 3, 2, true},
        Case{"bgr16", 3, 2, false}, Case{"rgba16", 4, 2, true}, Case{"bgra16", 4, 2, false},
        Case{"16UC4", 4, 2, false}}) {
    for (const bool big_endian : {false, true}) {
      if (c.depth == 1 && big_endian) continue;
      const int bpp = c.channels * c.depth;
      const std::string cdr =
          message(c.encoding, w, h, bpp, w * bpp + 3, big_endian, [&](int x, int y, auto* p) {
            const Rgb s = scene(x, y);
            const int r = wide(s.r, x, y, 0), g = wide(s.g, x, y, 1), b = wide(s.b, x, y, 2);
            const int first = c.rgb ? r : b, third = c.rgb ? b : r;
            if (c.depth == 1) {
              p[0] = static_cast<unsigned char>(c.rgb ? s.r : s.b);
              p[1] = static_cast<unsigned char>(s.g);
              p[2] = static_cast<unsigned char>(c.rgb ? s.b : s.r);
              if (c.channels == 4) p[3] = 0x80;
            } else {
              put16(p, first, big_endian);
              put16(p + 2, g, big_endian);
              put16(p + 4, third, big_endian);
              if (c.channels == 4) put16(p + 6, 0x1234, big_endian);
            }
          });
      const Image8 grey = ros2::raw_image_grey(cdr).image;
      ASSERT_EQ(grey.width, w);
      ASSERT_EQ(grey.height, h);
      const cv::Mat want = opencv_grey(w, h, c.depth == 2);
      int differ = 0, off_itu = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          // OpenCV rounds its 16-bit grey its own way: its high byte may be one level off
          // where the grey is at a multiple of 256.
          differ += std::abs(grey.at(x, y) - want.at<std::uint8_t>(y, x)) > c.depth - 1;
          // And ITU-R 601 itself, so that a channel order both sides got wrong is seen.
          const Rgb s = scene(x, y);
          off_itu += std::abs(grey.at(x, y) - (0.299 * s.r + 0.587 * s.g + 0.114 * s.b)) > 1.0;
        }
      EXPECT_EQ(differ, 0) << c.encoding << (big_endian ? " big endian" : "");
      EXPECT_EQ(off_itu, 0) << c.encoding << (big_endian ? " big endian" : "");
    }
  }
}

TEST(RawImage, PackedYuvGivesItsLuma) {
  const int w = 37, h = 9;  // an odd width: the last pixel's pair is half used
  auto luma = [](int x, int y) { return (x * 13 + y * 29) % 256; };
  for (const bool uyvy : {false, true}) {
    for (const char* encoding : uyvy ? std::vector<const char*>{"uyvy", "yuv422"}
                                     : std::vector<const char*>{"yuyv", "yuv422_yuy2"}) {
      const std::string cdr =
          message(encoding, w, h, 2, w * 2 + 1, false, [&](int x, int y, auto* p) {
            const int chroma = x % 2 == 0 ? 90 : 200;  // U for even pixels, V for odd ones
            p[uyvy ? 1 : 0] = static_cast<unsigned char>(luma(x, y));
            p[uyvy ? 0 : 1] = static_cast<unsigned char>(chroma);
          });
      const Image8 grey = ros2::raw_image_grey(cdr).image;
      int differ = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) differ += grey.at(x, y) != luma(x, y);
      EXPECT_EQ(differ, 0) << encoding;
    }
  }
}

// A surface of one colour, as each of the four mosaics samples it: demosaicked, its luma; a
// pattern read as another would mix red and blue, or take green for them.
TEST(RawImage, BayerMosaicsOfOneColourGiveItsLuma) {
  const Rgb colour{200, 100, 50};
  const double want = 0.299 * colour.r + 0.587 * colour.g + 0.114 * colour.b;  // 124.2
  const int w = 16, h = 12;
  for (const char* pattern : {"rggb", "bggr", "gbrg", "grbg"}) {
    for (const int depth : {1, 2}) {
      for (const bool big_endian : {false, true}) {
        if (depth == 1 && big_endian) continue;
        const std::string encoding = std::string("bayer_") + pattern + (depth == 1 ? "8" : "16");
        const std::string cdr =
            message(encoding, w, h, depth, w * depth + 2, big_endian, [&](int x, int y, auto* p) {
              const char site = pattern[(y % 2) * 2 + x % 2];
              const int v = site == 'r' ? colour.r : site == 'g' ? colour.g : colour.b;
              if (depth == 1)
                p[0] = static_cast<unsigned char>(v);
              else
                put16(p, v * 257, big_endian);
            });
        const Image8 grey = ros2::raw_image_grey(cdr).image;
        ASSERT_EQ(grey.width, w);
        double worst = 0;
        for (int y = 2; y < h - 2; ++y)
          for (int x = 2; x < w - 2; ++x) worst = std::max(worst, std::abs(grey.at(x, y) - want));
        EXPECT_LE(worst, 1.0) << encoding << (big_endian ? " big endian" : "");
      }
    }
  }
}

TEST(RawImage, WhatCannotBeReadIsRefusedNamingIt) {
  auto refusal = [](const std::string& cdr) {
    try {
      ros2::raw_image_grey(cdr);
    } catch (const CdrError& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  auto fill = [](int, int, unsigned char* p) { p[0] = 1; };
  EXPECT_THAT(refusal(message("nv21", 4, 4, 1, 4, false, fill)),
              HasSubstr("encoding \"nv21\" is not read (mono8"));
  EXPECT_THAT(refusal(message("bayer_rggb8", 1, 8, 1, 1, false, fill)),
              HasSubstr("no whole 2 x 2 cell"));
  EXPECT_THAT(refusal(message("yuyv", 8, 2, 1, 8, false, fill)),
              HasSubstr("step 8 is shorter than a row (16 bytes)"));
  EXPECT_EQ(refusal(message("bgra16", 3, 2, 8, 24, false, fill)), "read");
  EXPECT_THAT(refusal(message("bgra16", 3, 2, 6, 18, false, fill)),
              HasSubstr("shorter than a row (24 bytes)"));
}

}  // namespace
}  // namespace lampnav::io
