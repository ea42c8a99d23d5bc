#pragma once
// The runtime loop: inputs in the order they arrive (odometry at its rate, camera frames with
// their real delay) go to the localizer; after each wheel reading the executor (when there are
// commands) turns the estimate into wheel speeds. The same loop runs a live robot, the simulated
// one and a recorded mission (replay), and with the same inputs gives the same outputs.

#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/fusion/localizer.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/navigation/executor.hpp"
#include "lampnav/navigation/input_faults.hpp"

namespace lampnav::navigation {

struct RuntimeOptions {
  fusion::LocalizerOptions localizer;
  ExecutorOptions executor;
  InputFaultOptions inputs;
  double max_duration_s = 3600;  // the loop stops after this much robot time
  // The starting pose's uncertainty when the robot is told where it starts.
  double start_sigma_m = 0.05, start_sigma_deg = 2.0;
  void validate() const;
};

// What the loop saw, for logs, replay outputs and reports.
class RuntimeObserver {
 public:
  virtual ~RuntimeObserver() = default;
  // After each wheel reading, once the localizer has a pose.
  virtual void on_estimate(const fusion::LocalizerEstimate& /*estimate*/) {}
  virtual void on_ceiling(const FrameInput& /*frame*/, const fusion::CeilingObservation& /*ob*/) {}
  virtual void on_omni(const FrameInput& /*frame*/, const vision::OmniDetection& /*detection*/) {}
  // A frame that is not an image of its camera (size, depth), with why.
  virtual void on_refused(const FrameInput& /*frame*/, const std::string& /*why*/) {}
  // A fault in an input stream (input_faults.hpp), as it arrives.
  virtual void on_input_fault(const InputFault& /*fault*/) {}
  // Route commands given while running: taken (why empty) or refused, with why.
  virtual void on_command(const CommandInput& /*command*/, const std::string& /*why*/) {}
  // An operator's pose estimate: taken as a fix (why empty) or refused by the filter, with why.
  virtual void on_pose_estimate(const PoseInput& /*pose*/, const std::string& /*why*/) {}
};

struct RunOutcome {
  ExecutorStatus status = ExecutorStatus::idle;  // idle: no commands were given
  std::string reason;                            // why the mission failed
  std::size_t wheel_readings = 0, ceiling_frames = 0, omni_frames = 0, refused_frames = 0;
  std::size_t commands = 0, refused_commands = 0;  // given while running
  std::size_t pose_estimates = 0;                  // an operator's, taken as fixes
  InputFaultCounts faults[3];                      // by InputStream
  std::optional<Stamp> first, last;                // robot time span
  bool time_limit = false;                         // stopped by max_duration_s
  double duration_s() const { return first && last ? to_seconds(*last - *first) : 0.0; }
};

class Runtime {
 public:
  // Throws InputError for bad options or a robot without what the localizer needs.
  Runtime(const graph::TopologicalMap& map, const RobotDescription& robot,
          const RuntimeOptions& options = {});

  // Runs until the robot has no more input, the commands are carried out or have failed, or the
  // time limit. With `start` the localizer starts there; without, it finds the robot from the omni
  // camera first. With commands, the executor starts once the robot's pose is known; commands
  // that arrive as input replace them. With `keep_running` the loop goes on after the mission
  // arrives or fails (a live robot waits for the next command); otherwise it ends there.
  RunOutcome run(Robot& robot, const std::optional<Pose2>& start,
                 const std::vector<graph::RouteCommand>& commands,
                 RuntimeObserver* observer = nullptr, bool keep_running = false);

  const fusion::Localizer& localizer() const { return localizer_; }
  const Executor& executor() const { return executor_; }

 private:
  const graph::TopologicalMap* map_;
  RuntimeOptions o_;
  fusion::Localizer localizer_;
  Executor executor_;
  double semi_axis_;
  InputFaultMonitor inputs_;
};

}  // namespace lampnav::navigation
