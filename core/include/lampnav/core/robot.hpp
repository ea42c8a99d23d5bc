#pragma once
// The small interface the stack drives a robot through: wheel speeds out; wheel readings, camera
// frames, route commands and an operator's pose estimates in, in the order they arrive. A real
// robot (the DDS node, ros/), the simulated one (sim/) and a recorded mission (replay) all stand
// behind it.

#include <optional>
#include <string>
#include <variant>

#include "lampnav/core/image.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"

namespace lampnav {

enum class CameraRole { ceiling, omni };

struct WheelInput {
  Stamp stamp;                 // read at
  double left = 0, right = 0;  // cumulative travel of each wheel, m
};

struct FrameInput {
  CameraRole camera = CameraRole::ceiling;
  Stamp capture;  // when the picture was taken
  Stamp arrival;  // when it reached the stack (capture + transfer + processing)
  Image8 image;
};

// Route commands given while the robot runs (shared/spec/cli.md's command text). They replace
// the mission in progress.
struct CommandInput {
  Stamp arrival;
  std::string text;
};

// Where an operator says the robot is (RViz's or Foxglove's "2D Pose Estimate", published on
// /initialpose): taken as a fix at `arrival`, with its covariance over (x, y, yaw). The cameras
// then confirm it or, if it is wrong, find the robot as after a carry.
struct PoseInput {
  Stamp arrival;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

using RobotInput = std::variant<WheelInput, FrameInput, CommandInput, PoseInput>;

class Robot {
 public:
  virtual ~Robot() = default;
  // Wheel speeds (m/s) to hold until the next call. A recorded robot ignores them.
  virtual void set_wheel_speeds(double left, double right) = 0;
  // The next input in arrival order; nullopt when there will be no more. A real robot waits for
  // it; a simulated or recorded one produces it at once.
  virtual std::optional<RobotInput> next() = 0;
};

}  // namespace lampnav
