#pragma once
// Little-endian encoding and bounds-checked decoding of MCAP's primitive types.

#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

namespace lampnav::io::detail {

class ByteWriter {
 public:
  void u8(std::uint8_t v) { buf_.push_back(static_cast<char>(v)); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void str(const std::string& s) {  // uint32 length + bytes
    u32(static_cast<std::uint32_t>(s.size()));
    buf_ += s;
  }
  void bytes64(const std::string& s) {
    u64(s.size());
    buf_ += s;
  }
  void raw(const std::string& s) { buf_ += s; }
  void string_map(const std::map<std::string, std::string>& m) {
    ByteWriter inner;
    for (const auto& [k, v] : m) {
      inner.str(k);
      inner.str(v);
    }
    str(inner.buf_);
  }
  std::string& data() { return buf_; }
  std::size_t size() const { return buf_.size(); }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) buf_.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  std::string buf_;
};

// A record's content ran out before a field ended.
struct Malformed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class ByteReader {
 public:
  ByteReader(const char* data, std::size_t size) : p_(data), n_(size) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1, "uint8")); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(le(2, "uint16")); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4, "uint32")); }
  std::uint64_t u64() { return le(8, "uint64"); }
  std::string str() { return take(u32(), "string"); }
  std::string bytes64() {
    const std::uint64_t len = u64();
    if (len > remaining())
      throw Malformed("a byte array of " + std::to_string(len) +
                      " bytes runs past the record's end");
    return take(static_cast<std::size_t>(len), "bytes");
  }
  std::string rest() { return take(remaining(), "bytes"); }
  std::map<std::string, std::string> string_map() {
    const std::uint32_t len = u32();
    if (len > remaining())
      throw Malformed("a map of " + std::to_string(len) + " bytes runs past the record's end");
    ByteReader inner(p_ + i_, len);
    i_ += len;
    std::map<std::string, std::string> m;
    while (inner.remaining() > 0) {
      std::string k = inner.str();
      m[k] = inner.str();
    }
    return m;
  }
  ByteReader sub(std::size_t len) {
    if (len > remaining()) throw Malformed("a nested array runs past the record's end");
    ByteReader r(p_ + i_, len);
    i_ += len;
    return r;
  }
  std::size_t remaining() const { return n_ - i_; }
  std::size_t offset() const { return i_; }

 private:
  std::uint64_t le(std::size_t n, const char* what) {
    if (remaining() < n) throw Malformed(std::string("the record ends inside a ") + what);
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < n; ++k)
      v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(p_[i_ + k])) << (8 * k);
    i_ += n;
    return v;
  }
  std::string take(std::size_t len, const char* what) {
    if (len > remaining()) {
      throw Malformed(std::string("a ") + what + " of " + std::to_string(len) +
                      " bytes runs past the record's end");
    }
    std::string s(p_ + i_, len);
    i_ += len;
    return s;
  }
  const char* p_;
  std::size_t n_;
  std::size_t i_ = 0;
};

}  // namespace lampnav::io::detail
