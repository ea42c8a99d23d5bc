#pragma once
// Subcommands of the `lampnav` program. Each registers itself on the app and sets `run` to the
// job to do once the command line is parsed; the job returns the exit status (cli.md) and
// throws lampnav errors, which main() turns into messages.

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"

namespace CLI {
class App;
}

namespace lampnav::io {
struct MissionLog;
struct BagTopics;
struct FrameTransform;
struct CameraInfo;
}  // namespace lampnav::io

namespace lampnav::apps {

using Job = std::function<int()>;

void add_map_commands(CLI::App& app, Job& run);
void add_map_build_command(CLI::App& map, Job& run);   // map build (under `map`)
void add_map_survey_command(CLI::App& map, Job& run);  // map survey (under `map`)
void add_route_command(CLI::App& app, Job& run);
void add_sim_command(CLI::App& app, Job& run);
void add_locate_command(CLI::App& app, Job& run);
void add_run_commands(CLI::App& app, Job& run);   // run, replay
void add_robot_command(CLI::App& app, Job& run);  // robot import
void add_node_command(CLI::App& app, Job& run);   // node (ROS 2 over DDS)

// A bundled file (maps/..., maps/robots/...): under $LAMPNAV_DATA_DIR, or the source tree.
std::string data_path(const std::string& relative);

// A progress bar on stderr, drawn only when stderr is a terminal and not `quiet`.
class ProgressBar {
 public:
  explicit ProgressBar(bool quiet);
  void update(double fraction, const std::string& what = {});
  void done();

 private:
  bool show_;
  int last_ = -1;
};

// The robot of a command reading a log: `robot_path` when given, else the log's robot.json
// attachment; InputError naming the log otherwise. `text`, when given, receives the JSON read.
RobotDescription robot_for_log(const io::MissionLog& log, const std::string& log_path,
                               const std::string& robot_path, std::string* text = nullptr);

// --ceiling-topic, --omni-topic and --odometry-topic: which topics of a ROS 2 bag are the inputs.
void add_bag_topic_options(CLI::App& command, io::BagTopics& topics);
// A mission log or ROS 2 bag for its camera frames, and the robot for it (robot_for_log): a
// bag's camera mounts from its transforms, and how its topics were taken said on stderr.
io::MissionLog read_log_for_cameras(const std::string& log_path, const std::string& robot_path,
                                    const io::BagTopics& topics, RobotDescription& robot,
                                    std::string* robot_text = nullptr);
// The same with the wheels: a mission log or ROS 2 bag and the robot for it (robot_for_log). A
// bag's odometry becomes the wheel travel of the robot's semi-axis, and how its topics were taken
// is said on stderr.
io::MissionLog read_log_for_robot(const std::string& log_path, const std::string& robot_path,
                                  const io::BagTopics& topics, RobotDescription& robot,
                                  std::string* robot_text = nullptr);

// The cameras' mounts from ROS transforms (a bag's /tf_static and /tf, the node's /tf_static)
// where they join base_footprint (or base_link) to the frame a camera's images are stamped with
// (`frame_of`: "" when the camera sent none); robot.json's mounts stay where they do not. Each
// camera's outcome is said on stderr as a note naming `source` and the transforms (`what`)
// unless `quiet`. Returns the cameras whose mount came from the transforms.
std::vector<std::string> mounts_from_tf(
    const std::vector<io::FrameTransform>& transforms,
    const std::function<std::string(const CameraDescription&)>& frame_of, const std::string& source,
    const std::string& what, RobotDescription& robot, bool quiet = false);

// Whether robot.json's `camera` is the camera its driver describes (a CameraInfo from `source`,
// a bag's topic or a live one): "" when they put every pixel of a grid over the image within
// 1 px of each other, else a warning's text (what differs, and what to do). An uncalibrated
// CameraInfo (K all zero) is not compared; one lampnav cannot read is said so.
std::string camera_info_disagreement(const CameraDescription& camera, const io::CameraInfo& info,
                                     const std::string& source);

// X,Y,YAW (m, m, rad) from a command-line option; InputError naming `flag` otherwise.
Pose2 parse_pose_option(const std::string& text, const std::string& flag);

// Prints a diagnostic line to stderr: "lampnav: <kind>: <text>".
void diagnostic(const std::string& kind, const std::string& text);

}  // namespace lampnav::apps
