#include "raw_pixels.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "lampnav/io/ros2_messages.hpp"  // CdrError

namespace lampnav::io::detail {

namespace {

enum class Layout { mono, rgb, bgr, yuyv, uyvy, bayer };

struct Encoding {
  const char* name;
  Layout layout;
  int channels;    // samples a pixel (a YUV 4:2:2 pixel: its Y and one of U, V)
  int depth;       // bytes a sample
  int bayer_code;  // cv::COLOR_Bayer*2GRAY, for a mosaic
};

// sensor_msgs/image_encodings.hpp's names. The OpenCV types are laid out as OpenCV lays out
// images: one channel grey, three BGR, four BGRA.
constexpr Encoding kEncodings[] = {
    {"mono8", Layout::mono, 1, 1, 0},
    {"8UC1", Layout::mono, 1, 1, 0},
    {"mono16", Layout::mono, 1, 2, 0},
    {"16UC1", Layout::mono, 1, 2, 0},
    {"bgr8", Layout::bgr, 3, 1, 0},
    {"8UC3", Layout::bgr, 3, 1, 0},
    {"rgb8", Layout::rgb, 3, 1, 0},
    {"bgra8", Layout::bgr, 4, 1, 0},
    {"8UC4", Layout::bgr, 4, 1, 0},
    {"rgba8", Layout::rgb, 4, 1, 0},
    {"bgr16", Layout::bgr, 3, 2, 0},
    {"16UC3", Layout::bgr, 3, 2, 0},
    {"rgb16", Layout::rgb, 3, 2, 0},
    {"bgra16", Layout::bgr, 4, 2, 0},
    {"16UC4", Layout::bgr, 4, 2, 0},
    {"rgba16", Layout::rgb, 4, 2, 0},
    {"yuyv", Layout::yuyv, 2, 1, 0},
    {"yuv422_yuy2", Layout::yuyv, 2, 1, 0},
    {"uyvy", Layout::uyvy, 2, 1, 0},
    {"yuv422", Layout::uyvy, 2, 1, 0},
    {"bayer_rggb8", Layout::bayer, 1, 1, cv::COLOR_BayerRGGB2GRAY},
    {"bayer_bggr8", Layout::bayer, 1, 1, cv::COLOR_BayerBGGR2GRAY},
    {"bayer_gbrg8", Layout::bayer, 1, 1, cv::COLOR_BayerGBRG2GRAY},
    {"bayer_grbg8", Layout::bayer, 1, 1, cv::COLOR_BayerGRBG2GRAY},
    {"bayer_rggb16", Layout::bayer, 1, 2, cv::COLOR_BayerRGGB2GRAY},
    {"bayer_bggr16", Layout::bayer, 1, 2, cv::COLOR_BayerBGGR2GRAY},
    {"bayer_gbrg16", Layout::bayer, 1, 2, cv::COLOR_BayerGBRG2GRAY},
    {"bayer_grbg16", Layout::bayer, 1, 2, cv::COLOR_BayerGRBG2GRAY},
};

// ITU-R 601 luma in 14-bit fixed point, rounded: OpenCV's own coefficients for 8-bit and
// 16-bit images, which sum to 1 << 14 (a grey pixel stays itself).
constexpr std::uint32_t kR = 4899, kG = 9617, kB = 1868;
std::uint32_t luma(std::uint32_t r, std::uint32_t g, std::uint32_t b) {
  return (r * kR + g * kG + b * kB + (1u << 13)) >> 14;
}

}  // namespace

const char* raw_encodings_read() {
  return "mono8, mono16, rgb8, bgr8, rgba8, bgra8, rgb16, bgr16, rgba16, bgra16, yuyv, uyvy, "
         "bayer_rggb8, bayer_bggr8, bayer_gbrg8, bayer_grbg8 and their 16-bit forms; 8UC1, 8UC3, "
         "8UC4, 16UC1, 16UC3, 16UC4";
}

Image8 grey_from_raw(const RawPixels& raw) {
  const Encoding* e = nullptr;
  for (const Encoding& k : kEncodings)
    if (raw.encoding == k.name) e = &k;
  if (!e)
    throw CdrError("encoding \"" + raw.encoding + "\" is not read (" + raw_encodings_read() + ")");
  const std::uint32_t width = raw.width, height = raw.height, step = raw.step;
  if (width == 0 || height == 0 || width > 16384 || height > 16384)
    throw CdrError("image size " + std::to_string(width) + " x " + std::to_string(height) +
                   " is out of range");
  if (e->layout == Layout::bayer && (width < 2 || height < 2))
    throw CdrError("a " + raw.encoding + " image of " + std::to_string(width) + " x " +
                   std::to_string(height) + " holds no whole 2 x 2 cell of its mosaic");
  const std::uint64_t row = std::uint64_t(width) * e->channels * e->depth;
  if (step < row)
    throw CdrError("step " + std::to_string(step) + " is shorter than a row (" +
                   std::to_string(row) + " bytes)");
  const std::string& pixels = *raw.data;
  if (std::uint64_t(step) * height > pixels.size())
    throw CdrError("data holds " + std::to_string(pixels.size()) + " bytes, step x height is " +
                   std::to_string(std::uint64_t(step) * height));

  const auto* base = reinterpret_cast<const unsigned char*>(pixels.data());
  auto row_at = [&](std::uint32_t y) { return base + std::size_t(y) * step; };
  // A 16-bit sample as the message's byte order has it.
  const bool big = raw.big_endian;
  auto sample16 = [big](const unsigned char* p) -> std::uint32_t {
    return big ? (p[0] << 8 | p[1]) : (p[1] << 8 | p[0]);
  };
  const int w = static_cast<int>(width), h = static_cast<int>(height);
  Image8 grey(w, h);
  cv::Mat out(h, w, CV_8UC1, grey.pixels.data());

  switch (e->layout) {
    case Layout::mono:
      for (std::uint32_t y = 0; y < height; ++y) {
        const unsigned char* in = row_at(y);
        std::uint8_t* o = out.ptr<std::uint8_t>(static_cast<int>(y));
        if (e->depth == 1) {
          std::memcpy(o, in, width);
        } else {
          for (std::uint32_t x = 0; x < width; ++x)
            o[x] = static_cast<std::uint8_t>(sample16(in + 2 * x) >> 8);
        }
      }
      break;
    case Layout::rgb:
    case Layout::bgr: {
      const bool rgb = e->layout == Layout::rgb;
      if (e->depth == 1) {
        // OpenCV's conversion: the same fixed point and rounding as luma(), in SIMD.
        const cv::Mat in(h, w, e->channels == 3 ? CV_8UC3 : CV_8UC4,
                         const_cast<unsigned char*>(base), step);
        const int code = e->channels == 3 ? (rgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY)
                                          : (rgb ? cv::COLOR_RGBA2GRAY : cv::COLOR_BGRA2GRAY);
        cv::cvtColor(in, out, code);
        break;
      }
      const int r = rgb ? 0 : 2, b = rgb ? 2 : 0;
      for (std::uint32_t y = 0; y < height; ++y) {
        const unsigned char* in = row_at(y);
        std::uint8_t* o = out.ptr<std::uint8_t>(static_cast<int>(y));
        for (std::uint32_t x = 0; x < width; ++x) {
          const unsigned char* p = in + std::size_t(x) * e->channels * 2;
          o[x] = static_cast<std::uint8_t>(
              luma(sample16(p + 2 * r), sample16(p + 2), sample16(p + 2 * b)) >> 8);
        }
      }
      break;
    }
    case Layout::yuyv:
    case Layout::uyvy: {
      const int first = e->layout == Layout::yuyv ? 0 : 1;  // Y0 U Y1 V, or U Y0 V Y1
      for (std::uint32_t y = 0; y < height; ++y) {
        const unsigned char* in = row_at(y) + first;
        std::uint8_t* o = out.ptr<std::uint8_t>(static_cast<int>(y));
        for (std::uint32_t x = 0; x < width; ++x) o[x] = in[2 * x];
      }
      break;
    }
    case Layout::bayer:
      if (e->depth == 1) {
        const cv::Mat in(h, w, CV_8UC1, const_cast<unsigned char*>(base), step);
        cv::cvtColor(in, out, e->bayer_code);
      } else {
        cv::Mat in(h, w, CV_16UC1);
        for (std::uint32_t y = 0; y < height; ++y) {
          const unsigned char* r = row_at(y);
          auto* o = in.ptr<std::uint16_t>(static_cast<int>(y));
          for (std::uint32_t x = 0; x < width; ++x)
            o[x] = static_cast<std::uint16_t>(sample16(r + 2 * x));
        }
        cv::Mat grey16;
        cv::cvtColor(in, grey16, e->bayer_code);
        for (int y = 0; y < h; ++y) {
          const auto* g16 = grey16.ptr<std::uint16_t>(y);
          std::uint8_t* o = out.ptr<std::uint8_t>(y);
          for (int x = 0; x < w; ++x) o[x] = static_cast<std::uint8_t>(g16[x] >> 8);
        }
      }
      break;
  }
  return grey;
}

}  // namespace lampnav::io::detail
