#pragma once
// A simulated drive recorded to a temporary log and read back, as `lampnav sim` writes it and
// `lampnav replay` reads it. Header only, for the test binaries that link sim and io.

#include <filesystem>
#include <string>

#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

// `name`: the temporary log's file name, removed once read.
inline io::MissionLog recorded_drive(const sim::Scenario& s, const std::string& name) {
  const std::string path = temp_path(name);
  sim::record_mission(s, path);
  io::MissionLog log = io::read_mission_log(path);
  std::filesystem::remove(path);
  return log;
}

}  // namespace lampnav::test
