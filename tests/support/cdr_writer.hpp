#pragma once
// Writes CDR (XCDR1, either byte order) as rmw implementations do, for tests that build ROS 2
// messages and bags by hand: each primitive aligned to its size from the byte after the
// 4-byte encapsulation header.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace lampnav::test {

class CdrWriter {
 public:
  explicit CdrWriter(bool little_endian = true) : little_(little_endian) {
    out_ =
        std::string("\0", 1) + std::string(1, little_endian ? '\1' : '\0') + std::string(2, '\0');
  }
  CdrWriter& u8(std::uint8_t v) { return put(v); }
  CdrWriter& u32(std::uint32_t v) { return put(v); }
  CdrWriter& i32(std::int32_t v) { return put(static_cast<std::uint32_t>(v)); }
  CdrWriter& f64(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return put(b);
  }
  CdrWriter& string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    out_ += s;
    out_ += '\0';
    return *this;
  }
  CdrWriter& bytes(const std::string& b) {
    u32(static_cast<std::uint32_t>(b.size()));
    out_ += b;
    return *this;
  }
  CdrWriter& f64s(const std::vector<double>& v) {
    u32(static_cast<std::uint32_t>(v.size()));
    for (double x : v) f64(x);
    return *this;
  }
  CdrWriter& header(std::int64_t stamp_ns, const std::string& frame_id) {
    i32(static_cast<std::int32_t>(stamp_ns / 1'000'000'000));
    u32(static_cast<std::uint32_t>(stamp_ns % 1'000'000'000));
    return string(frame_id);
  }
  const std::string& data() const { return out_; }

 private:
  template <class T>
  CdrWriter& put(T v) {
    while ((out_.size() - 4) % sizeof(T)) out_ += '\0';
    for (std::size_t k = 0; k < sizeof(T); ++k) {
      const std::size_t shift = 8 * (little_ ? k : sizeof(T) - 1 - k);
      out_ += static_cast<char>((static_cast<std::uint64_t>(v) >> shift) & 0xFF);
    }
    return *this;
  }
  bool little_;
  std::string out_;
};

// ROS 2 messages as their CDR bytes.
inline std::string compressed_image_cdr(std::int64_t stamp_ns, const std::string& frame,
                                        const std::string& format, const std::string& data,
                                        bool little = true) {
  return CdrWriter(little).header(stamp_ns, frame).string(format).bytes(data).data();
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

}  // namespace lampnav::test
