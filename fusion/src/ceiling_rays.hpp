#pragma once
// Where an omni blob's ray meets the ceiling, for the global localizer's stray sightings and the
// omni check's blobs beyond the map: the ray from the camera, on a level floor, to the height
// most of the map's lamps hang at. Private to fusion.

#include <Eigen/Core>
#include <algorithm>
#include <optional>
#include <vector>

#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// The median lamp's height above a camera at `camera_z` (m); 0 for a map without lamps.
inline double usual_lamp_height(const graph::TopologicalMap& map, double camera_z) {
  std::vector<double> heights;
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps) heights.push_back(l.xyz.z() - camera_z);
  if (heights.empty()) return 0.0;
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  return heights[heights.size() / 2];
}

// Where the camera-frame unit `ray` meets the ceiling `height` (m) above a camera mounted at
// (mount_R, mount_t) on the robot, in the robot's base frame; none at or below the lamps' horizon.
inline std::optional<Eigen::Vector3d> ceiling_point(const Eigen::Matrix3d& mount_R,
                                                    const Eigen::Vector3d& mount_t,
                                                    const Eigen::Vector3d& ray, double height) {
  const Eigen::Vector3d d = mount_R * ray;  // level floor
  if (!(height > 0) || !(d.z() > 0.01)) return std::nullopt;
  return Eigen::Vector3d(mount_t + (height / d.z()) * d);
}

}  // namespace lampnav::fusion::detail
