#pragma once
// A reader of CDR, the encoding of ROS 2 messages on the wire and in bags (OMG DDS-XTYPES 1.3,
// "XCDR1" plain CDR as rmw implementations write it): a 4-byte encapsulation header (0x00 0x00
// big endian, 0x00 0x01 little endian; the two option bytes ignored), then the fields in order.
// Each primitive is aligned to its own size (8 at most), counted from the byte after the header;
// a string is a uint32 length including its terminating NUL, then the bytes; a sequence a uint32
// count, then the elements; a fixed-size array the elements alone.
// Every failure throws CdrError naming the field being read and the byte offset. CdrWriter
// writes the same encoding.

#include <cctype>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "lampnav/io/ros2_messages.hpp"  // CdrError

namespace lampnav::io {

class CdrReader {
 public:
  explicit CdrReader(const std::string& data) : data_(data) {
    if (data_.size() < 4) fail("encapsulation header", "message shorter than 4 bytes");
    if (data_[0] != 0 || (data_[1] != 0 && data_[1] != 1))
      fail("encapsulation header", "not plain CDR (representation " + hex(data_[0]) +
                                       hex(data_[1]) + "; only 0000 and 0001 are read)");
    little_ = data_[1] == 1;
    pos_ = 4;
  }

  std::uint8_t u8(const char* field) { return take<std::uint8_t>(field); }
  bool boolean(const char* field) { return take<std::uint8_t>(field) != 0; }
  std::uint16_t u16(const char* field) { return take<std::uint16_t>(field); }
  std::uint32_t u32(const char* field) { return take<std::uint32_t>(field); }
  std::int32_t i32(const char* field) {
    return static_cast<std::int32_t>(take<std::uint32_t>(field));
  }
  double f64(const char* field) {
    const std::uint64_t bits = take<std::uint64_t>(field);
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }

  std::string string(const char* field) {
    const std::uint32_t n = u32(field);
    if (n == 0) return {};  // some writers leave out the NUL of an empty string
    need(n, field);
    if (data_[pos_ + n - 1] != 0) fail(field, "string not NUL-terminated");
    std::string s = data_.substr(pos_, n - 1);
    pos_ += n;
    return s;
  }

  // A sequence's element count, checked against the bytes left (each element at least
  // `min_element_bytes`), so a corrupt count cannot ask for gigabytes.
  std::uint32_t count(const char* field, std::size_t min_element_bytes) {
    const std::uint32_t n = u32(field);
    if (min_element_bytes > 0 && n > (data_.size() - pos_) / min_element_bytes)
      fail(field, "sequence of " + std::to_string(n) + " elements in " +
                      std::to_string(data_.size() - pos_) + " bytes left");
    return n;
  }
  // uint8[] (a sequence of bytes: image data).
  std::string bytes(const char* field) {
    const std::uint32_t n = count(field, 1);
    std::string s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::vector<double> f64s(const char* field) {
    const std::uint32_t n = count(field, 8);
    std::vector<double> v(n);
    for (auto& x : v) x = f64(field);
    return v;
  }
  template <std::size_t N>
  void f64_array(double (&out)[N], const char* field) {
    for (auto& x : out) x = f64(field);
  }
  std::vector<std::string> strings(const char* field) {
    const std::uint32_t n = count(field, 4);
    std::vector<std::string> v(n);
    for (auto& s : v) s = string(field);
    return v;
  }

  std::size_t offset() const { return pos_; }

 private:
  template <class T>
  T take(const char* field) {
    // Alignment counts from the byte after the encapsulation header.
    const std::size_t rel = pos_ - 4, a = sizeof(T);
    const std::size_t pad = (a - rel % a) % a;
    need(pad + sizeof(T), field);
    pos_ += pad;
    unsigned char b[sizeof(T)];
    std::memcpy(b, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    T v = 0;
    for (std::size_t k = 0; k < sizeof(T); ++k) {
      const std::size_t i = little_ ? k : sizeof(T) - 1 - k;
      v |= static_cast<T>(static_cast<T>(b[i]) << (8 * k));
    }
    return v;
  }
  void need(std::size_t n, const char* field) const {
    if (n > data_.size() - pos_)
      fail(field, "message ends at byte " + std::to_string(data_.size()) + ", " +
                      std::to_string(n) + " more needed");
  }
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw CdrError("field " + field + " (byte " + std::to_string(pos_) + "): " + what);
  }
  static std::string hex(char c) {
    static const char* d = "0123456789abcdef";
    const auto u = static_cast<unsigned char>(c);
    return {d[u >> 4], d[u & 15]};
  }

  const std::string& data_;
  std::size_t pos_ = 0;
  bool little_ = true;
};

// Writes CDR as CdrReader reads it, in either byte order (little endian unless told).
class CdrWriter {
 public:
  explicit CdrWriter(bool little_endian = true) : little_(little_endian) {
    out_ = {'\0', little_endian ? '\1' : '\0', '\0', '\0'};
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
  CdrWriter& strings(const std::vector<std::string>& v) {
    u32(static_cast<std::uint32_t>(v.size()));
    for (const auto& x : v) string(x);
    return *this;
  }
  // std_msgs/msg/Header.
  CdrWriter& header(std::int64_t stamp_ns, const std::string& frame_id) {
    const std::int64_t sec =
        stamp_ns >= 0 ? stamp_ns / 1'000'000'000 : -((-stamp_ns + 999'999'999) / 1'000'000'000);
    i32(static_cast<std::int32_t>(sec));
    u32(static_cast<std::uint32_t>(stamp_ns - sec * 1'000'000'000));
    return string(frame_id);
  }
  const std::string& data() const { return out_; }
  std::string take() { return std::move(out_); }

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

// ASCII lower case, for matching topic and joint names.
inline std::string lower(std::string t) {
  for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return t;
}

}  // namespace lampnav::io
