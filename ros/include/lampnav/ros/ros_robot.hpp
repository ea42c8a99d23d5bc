#pragma once
// A robot on a ROS 2 system, behind lampnav::Robot: camera images, wheel odometry (or wheel
// joint states) and route commands come in over DDS; wheel speeds go out as a Twist on /cmd_vel,
// and the localizer's estimates as the pose, the map -> odom transform, the mode and the
// hypotheses (docs/ros2.md). Messages are queued by the DDS threads as bytes; images are decoded
// as they arrive on their camera's own thread, the rest on the caller's thread in next(). One
// that does not decode is counted and reported (topic, message number, field), never fatal.

#include <atomic>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot.hpp"
#include "lampnav/fusion/localizer.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav/ros/participant.hpp"

namespace lampnav::ros {

namespace detail {
enum class InputKind : int;
struct Inbox;
struct Pending;
}  // namespace detail

struct NodeTopics {
  // Images: sensor_msgs/msg/CompressedImage when the name ends in /compressed (image_transport's
  // convention), else sensor_msgs/msg/Image. Empty: that camera is not used.
  std::string ceiling_image = "/ceiling_camera/image_raw/compressed";
  std::string omni_image = "/omni_camera/image_raw/compressed";
  // Wheel odometry: nav_msgs/msg/Odometry, or, when joint_states is named, the two wheel joints
  // of sensor_msgs/msg/JointState (found by name as in bags) with the wheel radius.
  std::string odometry = "/odom";
  std::string joint_states, left_joint, right_joint;
  double wheel_radius = 0;
  std::string command = "/lampnav/command";  // std_msgs/msg/String, route command text
  // geometry_msgs/msg/PoseWithCovarianceStamped in the map frame: an operator's "2D Pose
  // Estimate" (RViz, Foxglove), taken as a fix. Empty: not subscribed.
  std::string pose_estimate = "/initialpose";
  // tf2_msgs/msg/TFMessage, transient local: the cameras' mounts (robot_state_publisher's, from
  // the robot's URDF). Empty: not subscribed.
  std::string tf_static = "/tf_static";
  std::string cmd_vel = "/cmd_vel";  // geometry_msgs/msg/Twist
  // diagnostic_msgs/msg/DiagnosticArray, where ROS's diagnostic tools look. Empty: none.
  std::string diagnostics = "/diagnostics";
  // Outputs under this namespace: pose, mode, hypotheses, events (and /tf).
  std::string ns = "/lampnav";
};

// A camera's calibration topic beside its images, as image_transport names it:
// "/ceiling_camera/image_raw/compressed" -> "/ceiling_camera/camera_info".
std::string camera_info_topic(const std::string& image_topic);

// REP-105 frames.
struct NodeFrames {
  std::string map = "map", odom = "odom", base = "base_link";
};

// A camera's image size in pixels (robot.json); 0 by 0: not known.
struct ImageSize {
  int width = 0, height = 0;
};

struct RosRobotOptions {
  NodeTopics topics;
  NodeFrames frames;
  double semi_axis = 0;  // m, from robot.json: odometry poses to wheel travel
  // Each camera's images are decoded on a thread of their own. Given the camera's size, that
  // thread decodes frames of it (JPEG and PNG) before the node subscribes, so that the first
  // images do not wait for the codecs' first use and for fresh memory (docs/ros2.md, "Latency").
  ImageSize ceiling_size, omni_size;
  std::size_t max_queue = 10000;  // messages waiting to be processed; beyond, the oldest image goes
  // Each camera's images waiting to be processed (decoding or decoded, not yet taken by next());
  // beyond, that camera's oldest waiting image is dropped (counted; not decoded unless its
  // decoding began). A node slower than its cameras then processes recent images, a bounded
  // time after they came, instead of falling further behind (docs/ros2.md, "Falling behind").
  std::size_t max_images_waiting = 5;
  // Every image is kept from the start until release_images() (a node that waits for its
  // cameras' mounts before it starts): those images are processed first, and the bound above
  // applies to the images that come after.
  bool hold_images = false;
  double idle_exit_s = 0;  // > 0: next() ends after this long with no input, once one came
  void validate() const;   // throws InputError naming the option
};

struct InputCounts {
  std::uint64_t received = 0, used = 0, refused = 0, dropped = 0;
};

struct NodeCounts {
  InputCounts ceiling, omni, odometry, commands, pose_estimates, static_transforms, camera_info;
  std::uint64_t poses_published = 0;
  // What was published last: the mode ("" before any estimate) and how many hypotheses.
  std::string mode;
  std::size_t hypotheses = 0;
};

class RosRobot : public Robot {
 public:
  // Subscribes and creates the writers. Throws InputError for bad options or topic names.
  RosRobot(Participant& participant, const RosRobotOptions& options);
  ~RosRobot() override;

  void set_wheel_speeds(double left, double right) override;
  // The next input in arrival order; waits for it. Nullopt after stop(), or after idle_exit_s.
  std::optional<RobotInput> next() override;
  // Makes next() return nullopt (from any thread).
  void stop();

  // Publishes an estimate: the pose and the map -> odom transform when certain; the mode when it
  // changes; the hypotheses (best first) when they change.
  void publish(const fusion::LocalizerEstimate& estimate);
  // A line on <ns>/events (commands taken or refused, the mission's end).
  void publish_event(const std::string& text);
  // The node's parts' health on the diagnostics topic, stamped with this machine's clock (from
  // any one thread; nothing when the topic is empty).
  void publish_diagnostics(const std::vector<io::ros2::DiagnosticStatus>& statuses);

  // When the input next() last returned arrived (for latency), and when it was ready (decoded):
  // from arrival to ready is decoding and queueing, from ready on the stack's processing.
  Clock::time_point last_arrival() const { return last_arrival_; }
  Clock::time_point last_ready() const { return last_ready_; }
  NodeCounts counts() const;
  // The newest sensor_msgs/msg/CameraInfo of `camera` (its driver's calibration, on the
  // camera_info topic beside its images: /a/image_raw[/compressed] -> /a/camera_info); nullopt
  // while none has come. Damaged ones are reported through on_problem by static_transforms().
  std::optional<io::CameraInfo> camera_info(CameraRole camera) const;
  // Ends hold_images: from now on each camera's waiting images are bounded.
  void release_images();
  // The frame_id of the first image of `camera` that came (before it is decoded); empty while
  // none has.
  std::string camera_frame(CameraRole camera) const;
  // The transforms that came on /tf_static so far, the latest of each child frame, in the order
  // the frames first came. Messages of /tf_static and camera_info that did not decode are
  // counted, and reported through on_problem by this call.
  std::vector<io::FrameTransform> static_transforms();
  // Called for each message refused, with the reason (topic, message number, field).
  std::function<void(const std::string&)> on_problem;

 private:
  std::optional<RobotInput> decode(detail::Pending& p);
  void subscribe(Participant& p, const std::string& topic, const std::string& type, Qos qos,
                 detail::InputKind kind);
  void subscribe_static_transforms(Participant& p);
  void subscribe_camera_info(Participant& p, const std::string& image_topic, CameraRole camera);
  const std::string& topic_of(detail::InputKind kind) const;
  // Closes the inbox: its callbacks drop what comes from then on; the decoding threads finish.
  void close();

  RosRobotOptions o_;
  Writer *cmd_vel_, *pose_, *tf_, *mode_, *hypotheses_, *events_, *diagnostics_ = nullptr;
  // What the DDS threads hand over (the queue, the counts, each camera's decoding thread), shared
  // with the participant's callbacks: the participant may call them after the robot is gone (it
  // outlives the robot), and they then find the inbox closed and drop the message.
  std::shared_ptr<detail::Inbox> inbox_;
  std::atomic<bool> stop_{false};

  // The loop thread's own.
  io::ros2::OdometryWheels odometry_wheels_;
  io::ros2::JointWheels joint_wheels_;
  std::optional<Stamp> last_wheel_stamp_;
  // The odometry frame's pose of the base at recent wheel readings, for map -> odom.
  std::deque<std::pair<Stamp, Pose2>> odom_;
  std::optional<WheelInput> last_wheels_;
  Clock::time_point last_arrival_{}, last_ready_{}, last_input_{};
  bool any_input_ = false;
  std::optional<fusion::LocalizerMode> last_mode_;
  std::size_t last_hypotheses_ = 0;
  double last_leader_weight_ = -1;
};

}  // namespace lampnav::ros
