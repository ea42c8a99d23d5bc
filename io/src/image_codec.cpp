#include <algorithm>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "lampnav/core/error.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

namespace {

std::string encode(const Image8& image, const char* ext, int parameter, int value) {
  const cv::Mat m(image.height, image.width, CV_8UC1,
                  const_cast<std::uint8_t*>(image.pixels.data()));
  std::vector<uchar> buf;
  cv::imencode(ext, m, buf, {parameter, value});
  return std::string(buf.begin(), buf.end());
}

}  // namespace

std::string encode_png(const Image8& image, int compression) {
  return encode(image, ".png", cv::IMWRITE_PNG_COMPRESSION, compression);
}

std::string encode_jpeg(const Image8& image, int quality) {
  return encode(image, ".jpg", cv::IMWRITE_JPEG_QUALITY, quality);
}

namespace {

// The width and height a PNG or JPEG header declares (0, 0 when it does not say), read before
// decoding so that a header asking for gigapixels is refused, not allocated.
std::pair<std::uint32_t, std::uint32_t> declared_size(const std::string& b, bool png) {
  auto u8 = [&](std::size_t i) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(b[i]));
  };
  auto be16 = [&](std::size_t i) { return u8(i) << 8 | u8(i + 1); };
  auto be32 = [&](std::size_t i) { return be16(i) << 16 | be16(i + 2); };
  if (png) return b.size() >= 24 ? std::pair{be32(16), be32(20)} : std::pair{0u, 0u};
  // JPEG: the markers after SOI, read as libjpeg reads them (jdmarker.c's next_marker): bytes
  // that are not a marker are skipped up to the next 0xFF, fill bytes 0xFF are skipped, and each
  // segment is passed over by its length. The first start-of-frame (C0..CF but C4, C8, CC) holds
  // height then width. A scan (DA) before any frame header, or no frame header at all: 0, 0.
  std::size_t i = 2;
  while (i + 1 < b.size()) {
    if (u8(i) != 0xFF) {
      ++i;  // an extraneous byte: libjpeg warns and skips it
      continue;
    }
    const std::uint32_t marker = u8(i + 1);
    if (marker == 0xFF) {
      ++i;
      continue;
    }
    if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD9)) {
      i += 2;  // a stuffed byte (extraneous here), TEM, RSTn, SOI, EOI: no length follows
      continue;
    }
    if (marker == 0xDA) return {0, 0};
    if (i + 3 >= b.size()) return {0, 0};
    const std::uint32_t length = be16(i + 2);
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
      return i + 8 < b.size() ? std::pair{be16(i + 7), be16(i + 5)} : std::pair{0u, 0u};
    i += 2 + length;
  }
  return {0, 0};
}

// OpenCV's allocator for one decoding: the first grey 8-bit buffer of `size` bytes is `pixels`,
// sized then (so a header OpenCV refuses costs nothing) and not freed by OpenCV; anything else is
// OpenCV's own memory, freed by it.
class IntoPixels : public cv::MatAllocator {
 public:
  IntoPixels(std::vector<std::uint8_t>& pixels, std::size_t size) : pixels_(pixels), size_(size) {}

  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, size_t* step,
                         cv::AccessFlag, cv::UMatUsageFlags) const override {
    std::size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step) {
        if (data && step[i] != kAutoStep)
          total = std::max(total, step[i]);
        else
          step[i] = total;
      }
      total *= static_cast<std::size_t>(sizes[i]);
    }
    auto* u = new cv::UMatData(this);
    if (data) {
      u->data = u->origdata = static_cast<uchar*>(data);
      u->flags |= cv::UMatData::USER_ALLOCATED;
    } else if (!given_ && type == CV_8UC1 && total == size_) {
      given_ = true;
      pixels_.resize(size_);
      u->data = u->origdata = pixels_.data();
      u->flags |= cv::UMatData::USER_ALLOCATED;
    } else {
      u->data = u->origdata = static_cast<uchar*>(cv::fastMalloc(total));
    }
    u->size = total;
    return u;
  }
  bool allocate(cv::UMatData* u, cv::AccessFlag, cv::UMatUsageFlags) const override {
    return u != nullptr;
  }
  void deallocate(cv::UMatData* u) const override {
    if (!u) return;
    if (!(u->flags & cv::UMatData::USER_ALLOCATED)) cv::fastFree(u->origdata);
    delete u;
  }

 private:
  static constexpr std::size_t kAutoStep = 0x7fffffff;  // CV_AUTOSTEP of OpenCV's C API
  std::vector<std::uint8_t>& pixels_;
  std::size_t size_;
  mutable bool given_ = false;
};

}  // namespace

Image8 decode_image(const std::string& bytes, const std::string& source) {
  if (bytes.empty()) throw InputError({source, "", ""}, "empty image");
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const bool png = bytes.size() >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0;
  const bool jpeg = bytes.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
  if (!png && !jpeg) throw InputError({source, "", ""}, "not a PNG or JPEG image");
  constexpr std::uint64_t kMaxPixels = 64ull << 20;  // 8192 x 8192
  const auto [w, h] = declared_size(bytes, png);
  // Nothing is decoded whose size is not known first: a JPEG with no frame header before its
  // scan would not decode anyway, and one the header scan missed could ask for gigapixels.
  if (!png && (w == 0 || h == 0))
    throw InputError({source, "", ""}, "JPEG without a frame header (SOF) before its scan");
  if (std::uint64_t(w) * h > kMaxPixels)
    throw InputError({source, "", ""}, "image of " + std::to_string(w) + " x " + std::to_string(h) +
                                           " pixels: more than lampnav reads");
  // imdecode reads the bytes in place (it does not write to its input). A grey 8-bit image, the
  // usual case, is decoded straight into the result's pixels: OpenCV asks IntoPixels for its
  // buffer, and gets the result's when the image is the size the header said. A frame is then not
  // allocated and copied twice (on this machine that was most of the time a frame took). The Mat
  // starts empty, so a header OpenCV refuses leaves it empty and is reported as such. A JPEG is
  // read as grey by libjpeg itself, which for a colour JPEG takes its luma and skips the colour
  // planes. Anything else comes back in a buffer of OpenCV's and is converted.
  const cv::Mat buf(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data()));
  Image8 out;
  out.width = static_cast<int>(w);
  out.height = static_cast<int>(h);
  IntoPixels into(out.pixels, std::size_t{w} * h);
  cv::Mat m;
  m.allocator = &into;
  try {
    cv::imdecode(buf, jpeg ? cv::IMREAD_GRAYSCALE : cv::IMREAD_UNCHANGED, &m);
  } catch (const cv::Exception& e) {
    throw InputError({source, "", ""}, std::string("image does not decode: ") + e.what());
  }
  if (m.empty())
    throw InputError({source, "", ""}, "image does not decode (not PNG or JPEG, or damaged)");
  if (!out.pixels.empty() && m.data == out.pixels.data() && m.type() == CV_8UC1 &&
      m.cols == out.width && m.rows == out.height)
    return out;
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 257.0);
  if (m.depth() != CV_8U)
    throw InputError({source, "", ""}, "unsupported image depth (8 or 16 bits per channel)");
  if (m.channels() == 3) cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
  if (m.channels() == 4) cv::cvtColor(m, m, cv::COLOR_BGRA2GRAY);
  Image8 grey(m.cols, m.rows);
  for (int y = 0; y < m.rows; ++y)
    std::copy_n(m.ptr<std::uint8_t>(y), m.cols, &grey.pixels[static_cast<std::size_t>(y) * m.cols]);
  return grey;
}

std::string ImageEncoding::to_string() const {
  return format == Format::png ? "png" : "jpeg:" + std::to_string(jpeg_quality);
}

bool ImageEncoding::operator==(const ImageEncoding& o) const {
  return format == o.format && jpeg_quality == o.jpeg_quality &&
         png_compression == o.png_compression;
}

ImageEncoding parse_image_encoding(const std::string& text, const std::string& where) {
  ImageEncoding e;
  if (text == "png") {
    e.format = ImageEncoding::Format::png;
    return e;
  }
  e.format = ImageEncoding::Format::jpeg;
  if (text == "jpeg" || text == "jpg") return e;
  for (const char* prefix : {"jpeg:", "jpg:"}) {
    const std::string p = prefix;
    if (text.compare(0, p.size(), p) != 0) continue;
    const std::string q = text.substr(p.size());
    const bool digits =
        !q.empty() && q.size() <= 3 && q.find_first_not_of("0123456789") == std::string::npos;
    const int quality = digits ? std::stoi(q) : 0;
    if (quality < 1 || quality > 100)
      throw InputError({"", "", where},
                       "JPEG quality \"" + q + "\" is not a whole number from 1 to 100");
    e.jpeg_quality = quality;
    return e;
  }
  throw InputError({"", "", where}, "image format \"" + text +
                                        "\" is not one of png, jpeg, jpeg:QUALITY (1 to 100)");
}

std::string encode_image(const Image8& image, const ImageEncoding& encoding) {
  return encoding.format == ImageEncoding::Format::png ? encode_png(image, encoding.png_compression)
                                                       : encode_jpeg(image, encoding.jpeg_quality);
}

}  // namespace lampnav::io
