#pragma once
// Faults in a robot's input streams, counted as they arrive (the runtime loop's, so a live robot,
// the simulator and a replay count alike): a stream that stops and comes back (a gap longer than
// its limit), a message stamped at the same instant as the one before it (a duplicate), one
// stamped before it (out of order, or the clock jumped back), and a clock that jumps forward (a
// gap in every stream at once shows as one gap in each). What the localizer does with such input
// is its own (the EKF refuses readings back in time and frames captured before its history,
// counted in LocalizerCounts); this says what came in.

#include <cstdint>
#include <optional>
#include <string>

#include "lampnav/core/robot.hpp"
#include "lampnav/core/time.hpp"

namespace lampnav::navigation {

enum class InputStream { wheels, ceiling, omni };
const char* to_string(InputStream s);

enum class InputFaultKind { gap, duplicate, out_of_order };
const char* to_string(InputFaultKind k);

struct InputFault {
  InputStream stream;
  InputFaultKind kind;
  Stamp at;                  // the stamp of the message that showed it
  double seconds = 0;        // gap: how long nothing came; out of order: how far back
  std::string text() const;  // "ceiling camera: nothing for 30.0 s before 50.0 s"
};

struct InputFaultOptions {
  double wheels_gap_s = 1.0;  // odometry comes at tens of Hz
  double camera_gap_s = 5.0;  // cameras at a few Hz, the omni one slower
  void validate() const;
};

struct InputFaultCounts {
  std::uint64_t gaps = 0, duplicates = 0, out_of_order = 0;
  double longest_gap_s = 0;
  std::uint64_t total() const { return gaps + duplicates + out_of_order; }
};

class InputFaultMonitor {
 public:
  explicit InputFaultMonitor(const InputFaultOptions& options = {});
  // Looks at one input; the fault it shows, if any, is counted and returned. Commands are not
  // stamped.
  std::optional<InputFault> check(const RobotInput& input);
  const InputFaultCounts& counts(InputStream s) const { return counts_[static_cast<int>(s)]; }

 private:
  InputFaultOptions o_;
  InputFaultCounts counts_[3];
  bool seen_[3] = {false, false, false};
  Stamp last_[3];
};

}  // namespace lampnav::navigation
