#pragma once
// ROS 2 bags in MCAP (mission-log.md, "ROS 2 bags"): which channels are lampnav's inputs, and
// their CDR messages decoded.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "decoded_message.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

// The input channels of a bag, chosen once per file.
struct Ros2Channels {
  const McapChannel *ceiling = nullptr, *omni = nullptr;
  // Wheel odometry: nav_msgs/msg/Odometry, else the wheel joints of sensor_msgs/msg/JointState.
  const McapChannel *odometry = nullptr, *joints = nullptr;
  std::string left_joint, right_joint;         // as named (empty: found by name)
  std::map<std::uint16_t, std::string> types;  // each CDR channel's type ("sensor_msgs/Image")
};

// Chooses the channels as `topics` names them, else by name and type, and says how in `notes`.
// Throws InputError (naming `path` and listing the bag's topics) when a named topic is missing or
// of the wrong type, or when the topics cannot be told apart.
Ros2Channels choose_ros2_channels(const McapFile& file, const std::string& path,
                                  const BagTopics& topics, std::vector<std::string>& notes);

// One CDR message of `channel`: an input when the channel was chosen (or a camera calibration),
// bad (with the reason) when it does not decode, none otherwise.
void decode_ros2(const Ros2Channels& channels, const McapChannel& channel,
                 const McapMessage& message, DecodedMessage& out);

}  // namespace lampnav::io
