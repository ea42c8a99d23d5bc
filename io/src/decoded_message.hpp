#pragma once
// One message of a log or bag, decoded on a worker thread and kept until the log is put together
// in the file's order (read_mission_log).

#include <memory>
#include <string>
#include <vector>

#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

struct DecodedMessage {
  enum class Kind {
    none,  // not an input (a replay's own outputs, a user's extras, an unchosen topic)
    wheels,
    ceiling,
    omni,
    truth,
    event,
    command,
    odometry,
    joints,
    camera_info,
    transforms,
    bad,
  } kind = Kind::none;
  Logged<WheelReading> wheel;
  Logged<ImageFrame> image;  // ceiling, omni
  Logged<TruthPose> truth;
  Logged<MissionEvent> event;
  Logged<CommandMessage> command;
  Logged<OdometryPose> odometry;
  Logged<WheelJoints> joints;
  std::unique_ptr<CameraInfo> camera_info;  // with its topic in `topic` (rare, and large)
  std::vector<FrameTransform> transforms;
  std::string topic;
  std::string problem;  // bad: what, naming the topic and the message
};

// "TOPIC message N (TYPE): what (skipped)", as the log's problems read (no type: no brackets).
inline std::string skipped(const McapChannel& channel, const McapMessage& message,
                           const std::string& what, const std::string& type = {}) {
  return channel.topic + " message " + std::to_string(message.sequence) +
         (type.empty() ? "" : " (" + type + ")") + ": " + what + " (skipped)";
}

}  // namespace lampnav::io
