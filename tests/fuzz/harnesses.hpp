#pragma once
// One harness per input lampnav reads from outside (issue 17). Each takes arbitrary bytes and
// holds the library's contract: a value or the typed error (InputError, InputErrors, CdrError),
// never a crash, a hang or another exception; and where a value comes back, writing it and reading
// it again gives the same value. The libFuzzer programs (tests/fuzz/fuzzer_main.cpp, built by
// `make fuzz`) call them; the regression test (corpus_test.cpp, in `make test`) runs them over the
// seed corpora and every input a fuzzer ever crashed on (tests/fuzz/regressions/).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lampnav::fuzz {

using Harness = void (*)(const std::uint8_t* data, std::size_t size);

void map_geojson(const std::uint8_t* data, std::size_t size);
void robot_json(const std::uint8_t* data, std::size_t size);
void mcap(const std::uint8_t* data, std::size_t size);
void mission_log(const std::uint8_t* data, std::size_t size);
void route_commands(const std::uint8_t* data, std::size_t size);
void image(const std::uint8_t* data, std::size_t size);
void ros2_cdr(const std::uint8_t* data, std::size_t size);
void calibration(const std::uint8_t* data, std::size_t size);

struct Named {
  const char* name;  // also the corpus folder: tests/fuzz/corpus/<name>/
  Harness run;
};
inline const std::vector<Named>& all() {
  static const std::vector<Named> list = {
      {"map_geojson", map_geojson}, {"robot_json", robot_json},         {"mcap", mcap},
      {"mission_log", mission_log}, {"route_commands", route_commands}, {"image", image},
      {"ros2_cdr", ros2_cdr},       {"calibration", calibration},
  };
  return list;
}

// A broken contract: aborts with the message (a fuzzer reports it as a crash with its input).
[[noreturn]] void broken(const std::string& what);

}  // namespace lampnav::fuzz
