#pragma once
// Blobs far smaller than any lamp of the map can be at their angle off the omni camera's axis are
// spurious lights (a window's glint, a reflection): they say nothing of where the lamps are. A
// lamp's angular radius is at least about its smallest dimension over its range, and its range
// from a camera below a ceiling at height h grows as h / cos(theta); a quarter of that bound is
// the limit. One rule for the omni check and the global localizer's seeds.

#include <algorithm>
#include <cmath>

#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// The limit for the map's lamps seen from a camera at height `camera_z` (m): per cosine of the
// angle off the axis, in radians.
inline double spurious_blob_limit(const graph::TopologicalMap& map, double camera_z) {
  double smallest = 1e9, highest = 0;
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps) {
      smallest = std::min({smallest, l.length, l.width > 0 ? l.width : l.length});
      highest = std::max(highest, l.xyz.z() - camera_z);
    }
  return highest > 0 && smallest < 1e9 ? 0.25 * smallest / highest : 0.0;
}

// A blob `theta` (rad) off the axis with this angular radius (rad).
inline bool is_spurious_blob(double limit, double theta, double angular_radius) {
  return angular_radius < limit * std::cos(theta);
}

}  // namespace lampnav::fusion::detail
