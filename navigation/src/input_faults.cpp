#include "lampnav/navigation/input_faults.hpp"

#include <cstdio>

#include "lampnav/core/error.hpp"

namespace lampnav::navigation {

const char* to_string(InputStream s) {
  switch (s) {
    case InputStream::wheels:
      return "wheel odometry";
    case InputStream::ceiling:
      return "ceiling camera";
    case InputStream::omni:
      return "omni camera";
  }
  return "?";
}

const char* to_string(InputFaultKind k) {
  switch (k) {
    case InputFaultKind::gap:
      return "gap";
    case InputFaultKind::duplicate:
      return "duplicate";
    case InputFaultKind::out_of_order:
      return "out of order";
  }
  return "?";
}

std::string InputFault::text() const {
  char buf[160];
  const double t = to_seconds(at.time_since_epoch());
  switch (kind) {
    case InputFaultKind::gap:
      std::snprintf(buf, sizeof buf, "%s: nothing for %.1f s before %.2f s", to_string(stream),
                    seconds, t);
      break;
    case InputFaultKind::duplicate:
      std::snprintf(buf, sizeof buf, "%s: a second message stamped %.3f s", to_string(stream), t);
      break;
    case InputFaultKind::out_of_order:
      std::snprintf(buf, sizeof buf,
                    "%s: a message stamped %.3f s, %.3f s before the one before it",
                    to_string(stream), t, seconds);
      break;
  }
  return buf;
}

void InputFaultOptions::validate() const {
  if (!(wheels_gap_s > 0) || !(camera_gap_s > 0))
    throw InputError({"", "runtime options", "input gaps"}, "must be positive");
}

InputFaultMonitor::InputFaultMonitor(const InputFaultOptions& options) : o_(options) {
  o_.validate();
}

std::optional<InputFault> InputFaultMonitor::check(const RobotInput& input) {
  InputStream s;
  Stamp t;
  if (const auto* w = std::get_if<WheelInput>(&input)) {
    s = InputStream::wheels;
    t = w->stamp;
  } else if (const auto* f = std::get_if<FrameInput>(&input)) {
    s = f->camera == CameraRole::ceiling ? InputStream::ceiling : InputStream::omni;
    t = f->capture;
  } else {
    return std::nullopt;
  }
  const int i = static_cast<int>(s);
  std::optional<InputFault> out;
  if (seen_[i]) {
    const double dt = to_seconds(t - last_[i]);
    const double limit = s == InputStream::wheels ? o_.wheels_gap_s : o_.camera_gap_s;
    InputFaultCounts& c = counts_[i];
    if (dt == 0) {
      ++c.duplicates;
      out = InputFault{s, InputFaultKind::duplicate, t, 0};
    } else if (dt < 0) {
      ++c.out_of_order;
      out = InputFault{s, InputFaultKind::out_of_order, t, -dt};
    } else if (dt > limit) {
      ++c.gaps;
      c.longest_gap_s = std::max(c.longest_gap_s, dt);
      out = InputFault{s, InputFaultKind::gap, t, dt};
    }
  }
  // The stream's clock is the latest stamp seen: a message back in time does not move it back.
  if (!seen_[i] || t > last_[i]) last_[i] = t;
  seen_[i] = true;
  return out;
}

}  // namespace lampnav::navigation
