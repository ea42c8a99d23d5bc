#include "lampnav/core/time.hpp"

#include <cmath>

namespace lampnav {

Duration duration_from_seconds(double s) {
  return Duration(static_cast<std::int64_t>(std::llround(s * 1e9)));
}

Stamp stamp_from_seconds(double s) { return Stamp(duration_from_seconds(s)); }

}  // namespace lampnav
