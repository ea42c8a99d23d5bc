#pragma once
// Mission logs (shared/spec/mission-log.md): one MCAP file of JSON messages on fixed channels, with
// robot.json and map.geojson attached. Each message's `timestamp` is when its data was CAPTURED;
// the MCAP log_time is when it became AVAILABLE to the stack.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/image.hpp"
#include "lampnav/core/localizer_mode.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/io/mcap.hpp"

namespace lampnav::io {

namespace topics {
inline constexpr const char* kWheels = "/wheels";
inline constexpr const char* kCeilingImage = "/ceiling_camera/image";
inline constexpr const char* kOmniImage = "/omni_camera/image";
inline constexpr const char* kTruth = "/truth/pose";
inline constexpr const char* kEvents = "/events";
inline constexpr const char* kCommands = "/commands";
// What a replay adds.
inline constexpr const char* kPose = "/lampnav/pose";
inline constexpr const char* kEstimate = "/lampnav/estimate";
inline constexpr const char* kLamps = "/lampnav/lamps";
inline constexpr const char* kScene = "/lampnav/scene";
inline constexpr const char* kHypotheses = "/lampnav/hypotheses";
inline constexpr const char* kLog = "/lampnav/log";
}  // namespace topics

struct WheelReading {
  Stamp stamp;
  double left = 0, right = 0;  // m, cumulative wheel travel
};

struct ImageFrame {
  Stamp stamp;
  std::string frame_id;  // "ceiling_camera", "omni_camera"
  std::string format;    // "png" or "jpeg"
  std::string data;      // encoded bytes (base64 only on the wire)
};

struct TruthPose {
  Stamp stamp;
  Pose2 pose;
};

// What a mission event is, for programs. The log keeps the word it was written with (the spec's
// list is open: another tool's word is kept and read back as `other`).
enum class EventKind { kidnap, lamp_failure, frame_drop, other };
const char* to_string(EventKind kind);  // the spec's word ("other" for other)
EventKind event_kind(const std::string& word);

struct MissionEvent {
  MissionEvent() = default;
  MissionEvent(Stamp at, EventKind k, std::string what)
      : stamp(at), kind(to_string(k)), detail(std::move(what)) {}
  MissionEvent(Stamp at, std::string word, std::string what)
      : stamp(at), kind(std::move(word)), detail(std::move(what)) {}
  Stamp stamp;
  std::string kind;  // the log's word: "kidnap", "lamp_failure", "frame_drop", or another tool's
  std::string detail;
  EventKind type() const { return event_kind(kind); }
};

struct CommandMessage {
  Stamp stamp;
  std::string text;
};

// The fused estimate (/lampnav/pose and /lampnav/estimate).
struct PoseEstimate {
  Stamp stamp;
  Pose2 pose;
  std::array<double, 9> covariance{};        // row-major, x y yaw
  std::string node;                          // "" when in no region
  LocalizerMode mode = LocalizerMode::lost;  // never certain unless said; its word on the wire
};

// A line a person reads (/lampnav/log, foxglove.Log): what a replay used, missed or skipped.
struct LogMessage {
  enum class Level { debug = 1, info = 2, warning = 3, error = 4 };
  Stamp stamp;
  Level level = Level::info;
  std::string message;
  std::string name;  // who says it ("lampnav replay")
};

// Every place the robot may be while it does not know (/lampnav/hypotheses), with its weight.
struct HypothesisEntry {
  Pose2 pose;
  double weight = 0;
  std::string node;  // "" when in no region
};
struct Hypotheses {
  Stamp stamp;
  LocalizerMode mode = LocalizerMode::lost;
  std::vector<HypothesisEntry> hypotheses;  // best first; empty once one pose is known
};

// One frame's lamp detections (/lampnav/lamps): pixel centroid, orientation, area, track, label.
struct LampObservation {
  double u = 0, v = 0;     // px
  double orientation = 0;  // rad
  double area = 0;         // normalized units^2
  int track = 0;
  std::optional<std::string> label;  // the map lamp's id
};
struct LampObservations {
  Stamp stamp;
  std::string camera;
  std::vector<LampObservation> lamps;
};

// A drawing for viewers (foxglove.SceneUpdate): line strips, cubes and labels in the map frame.
struct SceneColor {
  double r = 0, g = 0, b = 0, a = 1;
};
struct SceneLine {
  std::vector<Eigen::Vector3d> points;
  SceneColor color;
  double thickness = 0.05;  // m
};
struct SceneCube {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  double yaw = 0;
  SceneColor color;
};
struct SceneText {
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  std::string text;
  SceneColor color;
  double size = 0.4;  // m
};
struct SceneEntity {
  std::string id;
  std::vector<SceneLine> lines;
  std::vector<SceneCube> cubes;
  std::vector<SceneText> texts;
};
struct SceneUpdate {
  Stamp stamp;
  std::vector<SceneEntity> entities;
};

// A record of a log with the time it became available.
template <class T>
struct Logged {
  Stamp log_time;
  T value;
};

class MissionLogWriter {
 public:
  MissionLogWriter(const std::string& path, McapWriterOptions options = {});
  ~MissionLogWriter();
  void attach_robot(const std::string& robot_json);
  void attach_map(const std::string& map_geojson);
  void write(Stamp available, const WheelReading& r);
  void write_image(Stamp available, const ImageFrame& f);  // channel chosen by frame_id
  void write(Stamp available, const TruthPose& t);
  void write(Stamp available, const MissionEvent& e);
  void write(Stamp available, const CommandMessage& c);
  // Replay outputs: the estimate goes to both /lampnav/pose and /lampnav/estimate.
  void write(Stamp available, const PoseEstimate& e);
  void write(Stamp available, const LampObservations& o);
  void write(Stamp available, const Hypotheses& h);
  void write(Stamp available, const LogMessage& m);
  void write(Stamp available, const SceneUpdate& u);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Which topics of a ROS 2 bag are the inputs (mission-log.md, "ROS 2 bags"). An empty one is
// guessed from the topic names and message types, and the guess said in MissionLog::notes.
struct BagTopics {
  std::string ceiling_image, omni_image, odometry;
  // sensor_msgs/msg/JointState, when the bag has no odometry: the topic and the two wheel
  // joints (guessed: the one joint named left and the one named right, "wheel" preferred).
  std::string joint_states, left_joint, right_joint;
  double wheel_radius = 0;  // m: joint angles to wheel travel (robot.json does not hold it)
};

// sensor_msgs/msg/JointState's two wheel positions (rad).
struct WheelJoints {
  Stamp stamp;
  double left = 0, right = 0;
};

// nav_msgs/msg/Odometry's pose: the robot base in its odometry frame.
struct OdometryPose {
  Stamp stamp;
  Pose2 pose;
};

// A transform of a ROS 2 bag's /tf or /tf_static: `child` frame in `parent` frame.
struct FrameTransform {
  Stamp stamp;
  std::string parent, child;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  bool is_static = false;  // from /tf_static
};

// sensor_msgs/msg/CameraInfo, as the bag gave it.
struct CameraInfo {
  Stamp stamp;
  std::string frame_id;
  int width = 0, height = 0;
  std::string distortion_model;  // "plumb_bob", "rational_polynomial", "equidistant", ...
  std::vector<double> d;
  std::array<double, 9> k{};
  std::array<double, 12> p{};
};

struct MissionLog {
  std::vector<Logged<WheelReading>> wheels;
  std::vector<Logged<OdometryPose>> odometry;     // a ROS 2 bag's (see wheels_from_odometry)
  std::vector<Logged<WheelJoints>> wheel_joints;  // a ROS 2 bag's (see wheels_from_joints)
  std::map<std::string, CameraInfo> camera_info;  // by topic, the last of each
  std::vector<FrameTransform> transforms;         // a ROS 2 bag's /tf_static and /tf, in order
  std::vector<Logged<ImageFrame>> ceiling_images, omni_images;
  std::vector<Logged<TruthPose>> truth;
  std::vector<Logged<MissionEvent>> events;
  std::vector<Logged<CommandMessage>> commands;
  std::optional<std::string> robot_json, map_geojson;
  McapReadReport report;              // container-level findings (truncation, skipped records)
  std::size_t skipped_messages = 0;   // messages refused for their content (bad JSON, base64, ...)
  std::vector<std::string> problems;  // one line per skipped message, naming topic and sequence
  bool ros2_bag = false;              // CDR messages were read (a ROS 2 bag)
  std::vector<std::string> notes;     // how the bag's topics were taken
};

// Reads a mission log, or a ROS 2 bag in MCAP (schema encoding ros2msg, message encoding cdr):
// sensor_msgs/msg/CompressedImage and Image (mono, colour, packed YUV and Bayer encodings, 8 or 16
// bits; any step: io/src/raw_pixels.hpp), nav_msgs/msg/Odometry, sensor_msgs/msg/CameraInfo. Throws
// InputError for a file that is not MCAP at all, and for a bag whose topics cannot be told apart
// (the message lists them); damaged content is skipped, counted and reported in the result.
MissionLog read_mission_log(const std::string& path, const BagTopics& topics = {});
// The same from the file's bytes (`source` names them in messages), and from a file read.
MissionLog parse_mission_log(const std::string& bytes, const std::string& source,
                             const BagTopics& topics = {});
MissionLog mission_log_of(const McapFile& file, const std::string& source,
                          const BagTopics& topics = {});

// A log's inputs in the order they became available (log time); at the same instant a wheel
// reading first, as the robot delivered them. `index` is into the log's vector of that kind.
struct LogInput {
  enum class Kind { wheels, ceiling, omni };
  Stamp arrival;
  Kind kind;
  std::size_t index;
};
std::vector<LogInput> inputs_in_arrival_order(const MissionLog& log, bool ceiling = true,
                                              bool omni = true);

// A bag's odometry as the wheel travel lampnav reads (conventions.md): each step of the odometry
// pose, split between the two wheels of a differential drive with this semi-axis (m). Nothing is
// done when the log has wheel readings of its own.
void wheels_from_odometry(MissionLog& log, double semi_axis);
// A bag's wheel joint positions (rad) as wheel travel (m) for wheels of this radius (m). Nothing
// is done when the log has wheel readings of its own.
void wheels_from_joints(MissionLog& log, double wheel_radius);

// The pose of `frame` in lampnav's `base` from a bag's transforms (REP-105: base_footprint, on the
// floor as lampnav's base is; else base_link, and `note` says so): the chain of transforms from
// the base to the frame, each the latest of its pair, static or not. A camera's optical frame
// (z along the optical axis, x to the image's right, y down the image) is lampnav's camera frame,
// so this is a camera's mount. Nullopt when no chain joins them.
struct MountFromTf {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();  // R = Rz(yaw) Ry(pitch) Rx(roll)
  std::string base;                               // the base frame used
};
std::optional<MountFromTf> mount_from_tf(const MissionLog& log, const std::string& frame);
// The same from transforms in the order they came (a live node's /tf_static).
std::optional<MountFromTf> mount_from_tf(const std::vector<FrameTransform>& transforms,
                                         const std::string& frame);

// The truth of a log at any instant, interpolated between the samples around it. A kidnap is a
// jump between two samples (more than 0.5 m): no interpolation across it.
class TruthTrack {
 public:
  explicit TruthTrack(std::vector<Logged<TruthPose>> truth);
  bool empty() const { return truth_.empty(); }
  Pose2 at(Stamp t) const;
  const std::vector<Logged<TruthPose>>& samples() const { return truth_; }  // by stamp

 private:
  std::vector<Logged<TruthPose>> truth_;
};

// Base64 (RFC 4648, with padding). decode throws std::invalid_argument naming the bad character.
std::string base64_encode(const std::string& bytes);
std::string base64_decode(const std::string& text);

// PNG for grey images (OpenCV's codec, kept out of this header).
std::string encode_png(const Image8& image, int compression = 3);
// JPEG (baseline, grey) at `quality` 1..100.
std::string encode_jpeg(const Image8& image, int quality);
// Decodes PNG or JPEG bytes to grey (colour is converted); throws InputError(`source`) when the
// bytes are not an image.
Image8 decode_image(const std::string& bytes, const std::string& source);

}  // namespace lampnav::io
