// lampnav: one program, subcommands as in shared/spec/cli.md. Exit status 0 success, 1 the job ran
// and failed, 2 bad input or usage. Only results go to stdout; diagnostics go to stderr.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/io/calibration.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::apps {
void diagnostic(const std::string& kind, const std::string& text) {
  // One write, so that lines from the node's threads do not interleave.
  std::cerr << ("lampnav: " + kind + ": " + text + "\n");
}

std::string data_path(const std::string& relative) {
  const char* env = std::getenv("LAMPNAV_DATA_DIR");
  return std::string(env && *env ? env : LAMPNAV_DATA_DIR) + "/" + relative;
}

Pose2 parse_pose_option(const std::string& text, const std::string& flag) {
  std::vector<double> v;
  std::stringstream s(text);
  std::string part;
  while (std::getline(s, part, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(part, &used));
      if (used != part.size() || !std::isfinite(v.back())) throw std::invalid_argument(part);
    } catch (const std::exception&) {
      throw InputError({"", flag, ""}, "'" + part +
                                           "' is not a number (expected X,Y,YAW: metres, "
                                           "metres, radians)");
    }
  }
  if (v.size() != 3)
    throw InputError({"", flag, ""},
                     "expected X,Y,YAW (metres, metres, radians), found '" + text + "'");
  return Pose2(v[0], v[1], wrap_angle(v[2]));
}

RobotDescription robot_for_log(const io::MissionLog& log, const std::string& log_path,
                               const std::string& robot_path, std::string* text) {
  std::string json_text;
  std::string source;
  if (!robot_path.empty()) {
    json_text = json::read_file(robot_path);
    source = robot_path;
  } else if (log.robot_json) {
    json_text = *log.robot_json;
    source = log_path + " (robot.json attachment)";
  } else {
    throw InputError({log_path, "attachments", "robot.json"},
                     "the log has no robot.json: give --robot");
  }
  RobotDescription robot = parse_robot_description(json_text, source);
  if (text) *text = std::move(json_text);
  return robot;
}

void add_bag_topic_options(CLI::App& command, io::BagTopics& topics) {
  command.add_option(
      "--ceiling-topic", topics.ceiling_image,
      "ROS 2 bag: the ceiling camera's image topic (default: the one named ceiling)");
  command.add_option("--omni-topic", topics.omni_image,
                     "ROS 2 bag: the omni camera's image topic (default: the one named omni or "
                     "fisheye)");
  command.add_option(
      "--odometry-topic", topics.odometry,
      "ROS 2 bag: the nav_msgs/msg/Odometry topic (default: the only one, or /odom)");
  command.add_option("--joint-states-topic", topics.joint_states,
                     "ROS 2 bag without odometry: the sensor_msgs/msg/JointState topic (default: "
                     "the only one, or /joint_states)");
  command.add_option("--left-joint", topics.left_joint,
                     "ROS 2 bag: the left wheel's joint (default: the one named left)");
  command.add_option("--right-joint", topics.right_joint,
                     "ROS 2 bag: the right wheel's joint (default: the one named right)");
  command
      .add_option("--wheel-radius", topics.wheel_radius,
                  "ROS 2 bag with wheel joints: the wheels' radius (m)")
      ->check(CLI::PositiveNumber);
}

namespace {

std::string triple(const Eigen::Vector3d& v) {
  std::ostringstream s;
  // + 0.0: a negative zero (from atan2) printed as 0.
  s << std::setprecision(4) << "[" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0
    << "]";
  return s.str();
}

}  // namespace

std::vector<std::string> mounts_from_tf(
    const std::vector<io::FrameTransform>& transforms,
    const std::function<std::string(const CameraDescription&)>& frame_of, const std::string& source,
    const std::string& what, RobotDescription& robot, bool quiet) {
  std::vector<std::string> taken;
  auto note = [&](const std::string& text) {
    if (!quiet) diagnostic("note", source + ": " + text);
  };
  for (auto& c : robot.cameras) {
    if (c.name != "ceiling_camera" && c.name != "omni_camera") continue;
    const std::string frame = frame_of(c);
    if (frame.empty()) continue;
    const auto m = io::mount_from_tf(transforms, frame);
    if (!m) {
      note("no transform of " + what + " joins base_footprint or base_link to " + frame + ": " +
           c.name + "'s mount from robot.json");
      continue;
    }
    note(c.name + " mount from " + what + " (" + m->base + " -> " + frame + "): xyz " +
         triple(m->xyz) + ", rpy " + triple(m->rpy) + " (robot.json: xyz " + triple(c.mount.xyz) +
         ", rpy " + triple(c.mount.rpy) + ")" +
         (m->base == "base_link" ? "; lampnav's base is on the floor: base_link must be too" : ""));
    c.mount.xyz = m->xyz;
    c.mount.rpy = m->rpy;
    taken.push_back(c.name);
  }
  return taken;
}

std::string camera_info_disagreement(const CameraDescription& camera, const io::CameraInfo& info,
                                     const std::string& source) {
  const auto not_read = [&](const std::string& why) {
    return source + " describes " + camera.name + " in a way lampnav does not read (" + why +
           "): robot.json's intrinsics were not checked against it";
  };
  std::optional<CameraDescription> theirs;
  double apart = 0;
  try {
    theirs = io::camera_from_info(info, source);
    if (!theirs) return "";  // uncalibrated: nothing to compare
    apart = vision::projection_difference_px(camera, *theirs);
  } catch (const InputError& e) {  // a model lampnav does not read
    return not_read(e.message());
  } catch (const Error& e) {  // or cannot project through
    return not_read(e.what());
  }
  std::ostringstream what;
  if (theirs->width != camera.width || theirs->height != camera.height) {
    what << "its images are " << theirs->width << " x " << theirs->height << " px, robot.json's "
         << camera.name << " " << camera.width << " x " << camera.height;
  } else {
    if (apart <= 1.0) return "";
    what << std::setprecision(3) << "its calibration (" << info.distortion_model << ", fx "
         << info.k[0] << ") puts pixels ";
    if (std::isfinite(apart))
      what << "up to " << apart << " px";
    else
      what << "out of view";
    what << " from where robot.json's " << camera.name << " (" << to_string(camera.model)
         << ") puts them";
  }
  return source + ": " + what.str() +
         ": robot.json is not this camera's calibration; if the camera's is right, import it "
         "(lampnav robot import, docs/cli.md)";
}

io::MissionLog read_log_for_cameras(const std::string& log_path, const std::string& robot_path,
                                    const io::BagTopics& topics, RobotDescription& robot,
                                    std::string* robot_text) {
  io::MissionLog log = io::read_mission_log(log_path, topics);
  robot = robot_for_log(log, log_path, robot_path, robot_text);
  if (log.ros2_bag) {
    for (const auto& n : log.notes) diagnostic("note", log_path + ": " + n);
    const auto first_frame = [&](const CameraDescription& c) {
      if (c.name != "ceiling_camera" && c.name != "omni_camera") return std::string();
      const auto& frames = c.name == "ceiling_camera" ? log.ceiling_images : log.omni_images;
      return frames.empty() ? std::string() : frames.front().value.frame_id;
    };
    if (!log.transforms.empty() &&
        !mounts_from_tf(log.transforms, first_frame, log_path, "the bag's transforms", robot)
             .empty() &&
        robot_text)
      *robot_text = to_robot_json(robot);
    // The bag's CameraInfo of each camera (by the frame its images are stamped with).
    for (const auto& c : robot.cameras) {
      const std::string frame = first_frame(c);
      if (frame.empty()) continue;
      for (const auto& [topic, info] : log.camera_info)
        if (info.frame_id == frame)
          if (const std::string w = camera_info_disagreement(c, info, log_path + ": " + topic);
              !w.empty())
            diagnostic("warning", w);
    }
  }
  return log;
}

io::MissionLog read_log_for_robot(const std::string& log_path, const std::string& robot_path,
                                  const io::BagTopics& topics, RobotDescription& robot,
                                  std::string* robot_text) {
  io::MissionLog log = read_log_for_cameras(log_path, robot_path, topics, robot, robot_text);
  if (log.ros2_bag) {
    io::wheels_from_odometry(log, robot.semi_axis);
    if (log.wheels.empty() && !log.wheel_joints.empty()) {
      if (!(topics.wheel_radius > 0))
        throw InputError({log_path, "topics", "--wheel-radius"},
                         "the bag's wheel odometry is wheel joint angles "
                         "(sensor_msgs/msg/JointState): give --wheel-radius");
      io::wheels_from_joints(log, topics.wheel_radius);
    }
  }
  return log;
}

ProgressBar::ProgressBar(bool quiet) : show_(!quiet && ::isatty(2)) {}

void ProgressBar::update(double fraction, const std::string& what) {
  if (!show_) return;
  const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100);
  if (percent == last_) return;
  last_ = percent;
  const int w = 40, filled = percent * w / 100;
  std::cerr << "\r[" << std::string(filled, '#') << std::string(w - filled, ' ') << "] " << percent
            << "% " << what << "\033[K" << std::flush;
}

void ProgressBar::done() {
  if (show_ && last_ >= 0) std::cerr << "\n";
  last_ = -1;
}
}  // namespace lampnav::apps

int main(int argc, char** argv) {
  using namespace lampnav;
  CLI::App app{"lampnav: indoor navigation by the ceiling lamps", "lampnav"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lampnav 0.1.0");
  apps::Job run;
  apps::add_map_commands(app, run);
  apps::add_route_command(app, run);
  apps::add_sim_command(app, run);
  apps::add_locate_command(app, run);
  apps::add_run_commands(app, run);
  apps::add_robot_command(app, run);
  apps::add_node_command(app, run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help (code 0) or the usage error
    return code == 0 ? 0 : 2;
  }
  try {
    return run ? run() : 2;
  } catch (const InputErrors& e) {
    for (const auto& p : e.problems()) apps::diagnostic("error", p.what());
    return 2;
  } catch (const InputError& e) {
    apps::diagnostic("error", e.what());
    return 2;
  } catch (const JobFailed& e) {
    apps::diagnostic("failed", e.what());
    return 1;
  } catch (const std::exception& e) {
    apps::diagnostic("error", e.what());
    return 1;
  }
}
