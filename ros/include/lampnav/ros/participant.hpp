#pragma once
// lampnav on the ROS 2 wire without a ROS installation: a DDS participant (eProsima Fast DDS, as
// ROS 2's default rmw) whose topics and types follow ROS 2's conventions: topic "/a/b" is DDS
// topic "rt/a/b", type "pkg/msg/Name" is "pkg::msg::dds_::Name_", and the QoS profiles are ROS 2's
// (rmw_qos_profile_sensor_data, rmw_qos_profile_default, tf2's broadcaster). Samples travel as
// their CDR bytes (encapsulation header included): io/ros2_messages.hpp decodes and encodes them,
// the same code that reads ROS 2 bags. Fast DDS stays out of this header.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace lampnav::ros {

// ROS 2's QoS profiles, as rclcpp names them.
enum class Qos {
  sensor_data,  // best effort, volatile, keep last 5 (cameras, odometry)
  state,        // reliable, volatile, keep last 10 (ROS 2's default)
  tf,           // reliable, volatile, keep last 100 (tf2_ros::TransformBroadcaster)
  // Reliable, transient local (a late joiner is sent what was published before it came): keep
  // last 1 writing, 100 reading (tf2_ros's static broadcaster and listener on /tf_static).
  tf_static,
};

// "/lampnav/pose" -> "rt/lampnav/pose". Throws InputError for a name ROS 2 would refuse.
std::string dds_topic(const std::string& ros_topic);
// "geometry_msgs/msg/Twist" -> "geometry_msgs::msg::dds_::Twist_".
std::string dds_type(const std::string& ros_type);
// ROS_DOMAIN_ID, else 0. Throws InputError when it is set and not 0..232.
int domain_from_environment();

using Clock = std::chrono::steady_clock;

struct Sample {
  std::string cdr;             // the serialized message, encapsulation header first
  Clock::time_point arrival;   // when the participant handed it over
  std::uint64_t sequence = 0;  // 1, 2, ... per subscription, in arrival order
};

class Writer {
 public:
  virtual ~Writer() = default;
  // False when DDS refused the sample (the reason goes to the participant's log).
  virtual bool write(const std::string& cdr) = 0;
  // Readers matched on the other side.
  virtual int matched() const = 0;
};

// Transports: shared memory between processes of one machine, UDP between machines. Camera images
// are large (an omni frame is 0.6 MB as PNG): Fast DDS's defaults (a 0.5 MB shared-memory segment,
// the system's default socket buffers) lose such samples under best effort, so both are raised.
// When FASTRTPS_DEFAULT_PROFILES_FILE names an XML profile, its transports are used instead.
struct ParticipantOptions {
  std::string name = "lampnav";
  std::uint32_t shm_segment_bytes = 32u << 20;   // this participant's outgoing samples
  std::uint32_t socket_buffer_bytes = 4u << 20;  // capped by net.core.rmem_max / wmem_max
};

class Participant {
 public:
  // Joins `domain` (0..232). Throws JobFailed when DDS cannot start (the message says why).
  explicit Participant(int domain, const ParticipantOptions& options = {});
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // Calls `on_sample` from a DDS thread for each sample that arrives, in order per topic. Keep it
  // short: hand the bytes over and return.
  void subscribe(const std::string& ros_topic, const std::string& ros_type, Qos qos,
                 std::function<void(Sample&&)> on_sample);
  // Writers live as long as the participant.
  Writer& writer(const std::string& ros_topic, const std::string& ros_type, Qos qos);
  // Writers matched on the other side of a subscription.
  int publishers_matched(const std::string& ros_topic) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::ros
