#pragma once
// The robot description, robot.json (conventions.md): wheels and cameras. Read strictly: an
// unknown key is an error, so a misspelt key never falls back to a default.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace lampnav {

// The pose of a camera frame in `base`: R = Rz(yaw) * Ry(pitch) * Rx(roll) (conventions.md).
struct Mount {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();  // rad: roll, pitch, yaw
  Eigen::Matrix3d rotation() const;
};

enum class CameraModelKind { pinhole, pajdla_bakstein, kannala_brandt };
// "pinhole", "pajdla_bakstein", "kannala_brandt": the model's name in robot.json.
const char* to_string(CameraModelKind k);
// The fisheye models: radially symmetric, a radius (px) for each angle off the optical axis.
inline bool is_fisheye(CameraModelKind k) {
  return k == CameraModelKind::pajdla_bakstein || k == CameraModelKind::kannala_brandt;
}

// OpenCV's radial-tangential model: [k1, k2, p1, p2, k3].
struct PinholeParameters {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px
  std::array<double, 5> distortion{};     // k1, k2, p1, p2, k3
};

// Pajdla-Bakstein: r = a tan(theta / b) + c sin(theta / d), valid beyond 90 degrees off-axis.
// Kannala-Brandt (model kannala_brandt; OpenCV's cv::fisheye, ROS's equidistant, Kalibr's
// pinhole-equi): r = fx theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8), u0 = cx,
// v0 = cy, beta = fy / fx; its fov_deg defaults to 180.
struct FisheyeParameters {
  double u0 = 0, v0 = 0;  // px, image centre
  double a = 0, b = 1, c = 0, d = 1;
  double beta = 1.0;          // pixel aspect ratio, applied to the radial term only
  double fov_deg = 185.0;     // full field of view, deg
  double f = 0;               // kannala_brandt: fx (px)
  std::array<double, 4> k{};  // kannala_brandt: k1 .. k4
};

struct CameraDescription {
  std::string name;
  CameraModelKind model = CameraModelKind::pinhole;
  int width = 0, height = 0;  // px
  PinholeParameters pinhole;  // when model == pinhole
  FisheyeParameters fisheye;  // when is_fisheye(model)
  Mount mount;
};

struct RobotDescription {
  std::string name;
  double semi_axis = 0.0;  // m, half the distance between the wheel contact points
  std::vector<CameraDescription> cameras;

  // The camera of that name, or nullptr.
  const CameraDescription* find_camera(const std::string& camera_name) const;
};

// Reads robot.json; throws InputError naming the file, the camera and the field.
RobotDescription read_robot_description(const std::string& path);
// Parses robot.json text; `source` names it in errors (a path, or "robot.json attachment").
RobotDescription parse_robot_description(const std::string& text, const std::string& source);
// Writes robot.json text that parse_robot_description reads back identically.
std::string to_robot_json(const RobotDescription& robot);

}  // namespace lampnav
