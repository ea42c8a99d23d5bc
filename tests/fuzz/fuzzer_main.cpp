// A libFuzzer program for one harness, chosen at build time (LAMPNAV_HARNESS, a function of
// harnesses.hpp).
#include "harnesses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  lampnav::fuzz::LAMPNAV_HARNESS(data, size);
  return 0;
}
