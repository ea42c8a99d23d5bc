#pragma once
// The ROS 2 messages lampnav reads and writes, as their CDR bytes (XCDR1 plain CDR with the
// 4-byte encapsulation header, as rmw implementations put them on the wire and in bags). One
// decoder per message for bags (mission_log.hpp) and the live node (ros/); one encoder per
// message the node publishes. Decoders read either byte order and throw CdrError naming the
// field and the byte offset; a count that asks for more elements than the bytes left can hold is
// refused before anything is allocated.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

struct CdrError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

namespace ros2 {

// --- Decoders (bytes in, lampnav values out) ---

// sensor_msgs/msg/CompressedImage: the bytes as they are (PNG or JPEG, told by their magic, not
// by the free-text `format`).
ImageFrame compressed_image(const std::string& cdr);
// sensor_msgs/msg/Image (mono, colour, packed YUV and Bayer encodings, 8 or 16 bits; any step:
// io/src/raw_pixels.hpp): grey, kept as a fast PNG.
ImageFrame raw_image(const std::string& cdr);
// The same as grey pixels, for a live node that has no use for the PNG.
struct GreyImage {
  Stamp stamp;
  std::string frame_id;
  Image8 image;
};
GreyImage raw_image_grey(const std::string& cdr);
// nav_msgs/msg/Odometry: the planar pose (yaw from the quaternion).
OdometryPose odometry(const std::string& cdr);
// sensor_msgs/msg/JointState: the positions of the two wheel joints, as named, or else the one
// joint whose name holds the side ("wheel" ones preferred).
WheelJoints wheel_joints(const std::string& cdr, const std::string& left_name,
                         const std::string& right_name);
CameraInfo camera_info(const std::string& cdr);
// std_msgs/msg/String.
std::string string_data(const std::string& cdr);
// tf2_msgs/msg/TFMessage (from /tf or /tf_static).
std::vector<FrameTransform> tf_transforms(const std::string& cdr);
// The std_msgs/msg/Header a message begins with (images, camera info, odometry, ...): read
// without the rest, for a node that must know a camera's frame before it decodes the image.
struct MessageHeader {
  Stamp stamp;
  std::string frame_id;
};
MessageHeader message_header(const std::string& cdr);
// geometry_msgs/msg/PoseWithCovarianceStamped, as RViz's and Foxglove's "2D Pose Estimate"
// publish on /initialpose: the planar pose and its covariance over (x, y, yaw). Refused when not
// finite, when the orientation is not a unit quaternion, or when the (x, y, yaw) covariance is
// not symmetric positive definite (a pose given as certain is not one lampnav may take).
struct PoseEstimate {
  Stamp stamp;
  std::string frame_id;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};
PoseEstimate pose_estimate(const std::string& cdr);

// --- Encoders (little endian, as ROS 2 writes on x86 and ARM) ---

struct Transform {
  Stamp stamp;
  std::string parent, child;  // frame ids
  Pose2 pose;                 // child in parent
};

// geometry_msgs/msg/PoseWithCovarianceStamped; `covariance` over (x, y, yaw), the others zero
// but for z, roll and pitch, which are given `fixed_variance` (the robot is planar).
std::string pose_with_covariance_stamped(Stamp stamp, const std::string& frame, const Pose2& pose,
                                         const Eigen::Matrix3d& covariance,
                                         double fixed_variance = 1e-9);
// geometry_msgs/msg/PoseArray.
std::string pose_array(Stamp stamp, const std::string& frame, const std::vector<Pose2>& poses);
// tf2_msgs/msg/TFMessage.
std::string tf_message(const std::vector<Transform>& transforms);
// The same with transforms in three dimensions (a camera's mount on /tf_static).
std::string tf_message(const std::vector<FrameTransform>& transforms);
// geometry_msgs/msg/Twist: forward speed (m/s) and turn rate (rad/s).
std::string twist(double forward, double turn);
// std_msgs/msg/String.
std::string string_message(const std::string& text);
// diagnostic_msgs/msg/DiagnosticStatus and DiagnosticArray: a part's health as ROS's diagnostic
// tools show it (rqt_robot_monitor, Foxglove's diagnostics panels).
struct DiagnosticStatus {
  enum Level : std::uint8_t { ok = 0, warn = 1, error = 2, stale = 3 };
  Level level = ok;
  std::string name, message, hardware_id;
  std::vector<std::pair<std::string, std::string>> values;  // key, value
};
std::string diagnostic_array(Stamp stamp, const std::vector<DiagnosticStatus>& statuses);
// What a robot's drivers publish (the test players and bag writers use them).
std::string compressed_image_message(Stamp stamp, const std::string& frame,
                                     const std::string& format, const std::string& data);
std::string odometry_message(Stamp stamp, const std::string& frame, const std::string& child,
                             const Pose2& pose);
std::string joint_state_message(Stamp stamp, const std::vector<std::string>& names,
                                const std::vector<double>& positions);

// --- Wheel travel from what ROS robots publish (conventions.md's wheel readings) ---

// Odometry poses, in capture order, as the travel of the two wheels of a differential drive: each
// step's chord (forwards or backwards) and its turn. The chord is the travel for odometry
// integrated by the midpoint rule (ROS's diff_drive_controller), and within ds dyaw^2 / 24 of it
// for exact arcs. The first pose gives travel 0; a pose not later than the last gives nothing.
class OdometryWheels {
 public:
  explicit OdometryWheels(double semi_axis) : semi_axis_(semi_axis) {}
  std::optional<WheelReading> add(const OdometryPose& odometry);

 private:
  double semi_axis_;
  std::optional<OdometryPose> last_;
  double left_ = 0, right_ = 0;
};

// Wheel joint angles (rad), in capture order, as travel (m) from the first reading.
class JointWheels {
 public:
  explicit JointWheels(double wheel_radius) : radius_(wheel_radius) {}
  std::optional<WheelReading> add(const WheelJoints& joints);

 private:
  double radius_;
  std::optional<WheelJoints> first_;
  std::optional<Stamp> last_;
};

}  // namespace ros2
}  // namespace lampnav::io
