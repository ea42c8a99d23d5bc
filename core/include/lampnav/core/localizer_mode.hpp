#pragma once
// What a localizer says of its pose: one type from the localizer (fusion) to what records and
// publishes it (io's mission log, the ROS node), so that no layer compares words. The words are
// the mission log's (spec/mission-log.md, /lampnav/estimate "mode") and are written only where
// a record leaves the process.

namespace lampnav {

enum class LocalizerMode { tracking, lost, relocalized, ambiguous };

// The mission log's word for `mode`.
constexpr const char* to_string(LocalizerMode mode) {
  switch (mode) {
    case LocalizerMode::tracking:
      return "tracking";
    case LocalizerMode::lost:
      return "lost";
    case LocalizerMode::relocalized:
      return "relocalized";
    case LocalizerMode::ambiguous:
      return "ambiguous";
  }
  return "?";
}

// Whether a pose in this mode is published as certain (tracking, relocalized); lost and
// ambiguous publish places the robot may be, never one pose.
constexpr bool is_certain(LocalizerMode mode) {
  return mode == LocalizerMode::tracking || mode == LocalizerMode::relocalized;
}

}  // namespace lampnav
