#pragma once
// Writing the text outputs of replays and reports.

#include <fstream>
#include <string>

#include "lampnav/core/error.hpp"

namespace lampnav::navigation {

// Throws InputError naming the file when it cannot be written.
inline void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError({path, "", ""}, "cannot write the file");
  out << text;
  if (!out) throw InputError({path, "", ""}, "write failed");
}

}  // namespace lampnav::navigation
