#pragma once
// Mission time: signed 64-bit nanoseconds on one clock per mission (conventions.md, MCAP's
// convention). A strong type on std::chrono, never a bare double in an interface.

#include <chrono>
#include <cstdint>

namespace lampnav {

using Duration = std::chrono::duration<std::int64_t, std::nano>;

// The clock of one mission. It has no now(): stamps come from sensors and logs, never from the
// wall clock, so that replays are deterministic.
struct MissionClock {
  using rep = std::int64_t;
  using period = std::nano;
  using duration = Duration;
  using time_point = std::chrono::time_point<MissionClock, Duration>;
  static constexpr bool is_steady = true;
};

using Stamp = MissionClock::time_point;

constexpr Stamp stamp_from_nanoseconds(std::int64_t ns) { return Stamp(Duration(ns)); }
constexpr std::int64_t to_nanoseconds(Stamp t) { return t.time_since_epoch().count(); }
constexpr std::int64_t to_nanoseconds(Duration d) { return d.count(); }
constexpr double to_seconds(Duration d) { return static_cast<double>(d.count()) * 1e-9; }
constexpr double to_seconds(Stamp t) { return to_seconds(t.time_since_epoch()); }
// Rounds to the nearest nanosecond.
Duration duration_from_seconds(double s);
Stamp stamp_from_seconds(double s);

}  // namespace lampnav
