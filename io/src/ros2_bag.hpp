#pragma once
// ROS 2 bags in MCAP (mission-log.md, "ROS 2 bags"): the CDR messages of the topics that are
// lampnav's inputs, decoded into a MissionLog.

#include <string>

#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

// Adds the bag's camera images, odometry and camera calibrations to `log`; damaged messages are
// skipped and reported there. Throws InputError (naming `path` and listing the bag's topics)
// when a named topic is missing or of the wrong type, or when the topics cannot be told apart.
void read_ros2_messages(const McapFile& file, const std::string& path, const BagTopics& topics,
                        MissionLog& log);

}  // namespace lampnav::io
