#include "drive_scale.hpp"

namespace lampnav::mapping {

void scale_drive(MappingResult& drive, double s, const Eigen::Vector2d& about, double camera_z) {
  for (auto& l : drive.lamps) {
    l.xyz.head<2>() = about + s * (l.xyz.head<2>() - about);
    l.xyz.z() = camera_z + s * (l.xyz.z() - camera_z);
    l.length *= s;
    l.width *= s;
  }
  for (auto& k : drive.keyframes) {
    k.pose = Pose2(about + s * (k.pose.translation() - about), k.pose.yaw());
    k.travel_m *= s;
  }
}

}  // namespace lampnav::mapping
