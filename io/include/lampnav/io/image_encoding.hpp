#pragma once
// How camera images are stored in a mission log (shared/spec/mission-log.md: PNG or JPEG, the
// message's `format` says which). PNG keeps every pixel; JPEG at a high quality keeps the lamps'
// centroids to a fraction of a pixel in a tenth of the bytes (docs/performance.md, "Logs").

#include <string>

#include "lampnav/core/image.hpp"

namespace lampnav::io {

struct ImageEncoding {
  enum class Format { png, jpeg };
  Format format = Format::jpeg;
  int jpeg_quality = 50;    // 1..100 (the default: docs/performance.md, "Logs")
  int png_compression = 1;  // 0..9: zlib's effort (noisy camera images gain little past 1)

  const char* format_name() const { return format == Format::png ? "png" : "jpeg"; }
  std::string to_string() const;  // "png" or "jpeg:Q", as parse_image_encoding reads it
  bool operator==(const ImageEncoding& o) const;
};

// Reads "png", "jpeg" (the default quality) or "jpeg:Q" with Q in 1..100. Throws InputError naming
// `where` (the option or field it came from) and the text otherwise.
ImageEncoding parse_image_encoding(const std::string& text, const std::string& where);

// The image's bytes in the chosen format (OpenCV's codecs, grey).
std::string encode_image(const Image8& image, const ImageEncoding& encoding);

}  // namespace lampnav::io
