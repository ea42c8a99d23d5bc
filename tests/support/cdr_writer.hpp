#pragma once
// CDR by hand for tests that build ROS 2 messages and bags, in either byte order and damaged:
// io's own writer (io/src/cdr.hpp) and the messages as robots publish them.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cdr.hpp"

namespace lampnav::test {

using io::CdrWriter;

inline std::string compressed_image_cdr(std::int64_t stamp_ns, const std::string& frame,
                                        const std::string& format, const std::string& data,
                                        bool little = true) {
  return CdrWriter(little).header(stamp_ns, frame).string(format).bytes(data).data();
}

// sensor_msgs/msg/Image in `encoding`, `height` rows of `step` bytes (a row's pixels and its
// padding), as a camera driver publishes it.
inline std::string raw_image_cdr(std::int64_t stamp_ns, const std::string& frame,
                                 const std::string& encoding, std::uint32_t width,
                                 std::uint32_t height, std::uint32_t step,
                                 const std::string& rows) {
  return CdrWriter()
      .header(stamp_ns, frame)
      .u32(height)
      .u32(width)
      .string(encoding)
      .u8(0)
      .u32(step)
      .bytes(rows)
      .take();
}
// A grey frame's pixels laid out as `encoding` holds them, every sample the grey (bgr8: three
// alike; yuyv: Y the grey, U and V neutral; bayer_rggb8: each site the grey), rows unpadded.
inline int raw_bytes_per_pixel(const std::string& encoding) {
  return encoding == "bgr8" ? 3 : encoding == "yuyv" ? 2 : 1;
}
inline std::string raw_rows(const std::vector<std::uint8_t>& grey, const std::string& encoding) {
  const int bytes = raw_bytes_per_pixel(encoding);
  std::string rows(grey.size() * bytes, '\0');
  for (std::size_t k = 0; k < grey.size(); ++k)
    for (int c = 0; c < bytes; ++c)
      rows[k * bytes + c] = bytes == 2 && c == 1 ? '\x80' : static_cast<char>(grey[k]);
  return rows;
}
inline std::string mono8_image_cdr(std::int64_t stamp_ns, const std::string& frame,
                                   std::uint32_t width, std::uint32_t height, std::uint32_t step,
                                   const std::string& rows) {
  return raw_image_cdr(stamp_ns, frame, "mono8", width, height, step, rows);
}

// nav_msgs/msg/Odometry with a planar pose (x, y, yaw) and zero twist.
inline std::string odometry_cdr(std::int64_t stamp_ns, double x, double y, double yaw,
                                bool little = true) {
  CdrWriter w(little);
  w.header(stamp_ns, "odom").string("base_link");
  w.f64(x).f64(y).f64(0).f64(0).f64(0).f64(std::sin(yaw / 2)).f64(std::cos(yaw / 2));
  for (int k = 0; k < 36; ++k) w.f64(0);
  for (int k = 0; k < 6 + 36; ++k) w.f64(0);
  return w.data();
}

// sensor_msgs/msg/CameraInfo: a camera matrix [fx 0 cx; 0 fy cy; 0 0 1] and distortion `d` of
// `model` (R the identity, P the camera matrix, no binning or region of interest), as a driver
// publishes its calibration.
inline std::string camera_info_cdr(std::int64_t stamp_ns, const std::string& frame,
                                   std::uint32_t width, std::uint32_t height,
                                   const std::string& model, const std::vector<double>& d,
                                   double fx, double fy, double cx, double cy, bool little = true) {
  CdrWriter w(little);
  w.header(stamp_ns, frame).u32(height).u32(width).string(model).f64s(d);
  for (double k : {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0}) w.f64(k);
  for (int k = 0; k < 9; ++k) w.f64(k % 4 == 0 ? 1.0 : 0.0);
  for (double p : {fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0}) w.f64(p);
  w.u32(0).u32(0).u32(0).u32(0).u32(0).u32(0).u8(0);
  return w.data();
}

}  // namespace lampnav::test
