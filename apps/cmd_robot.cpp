// lampnav robot import: robot.json's cameras from the calibration files of the usual tools (ROS
// camera_info, Kalibr camchain, OpenCV), keeping what a calibration does not know (the robot's
// wheels, each camera's mount).

#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <memory>

#include "commands.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/io/calibration.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::apps {
namespace {

struct ImportArgs {
  std::vector<std::string> calibrations;
  std::string robot, out, camera;
};

int run_import(const ImportArgs& a) {
  RobotDescription robot = read_robot_description(a.robot);
  std::vector<std::pair<std::string, io::ImportedCamera>> imported;  // file, camera
  for (const auto& path : a.calibrations)
    for (auto& c : io::read_calibration(path)) imported.emplace_back(path, std::move(c));
  if (!a.camera.empty() && imported.size() != 1)
    throw InputError({"", "--camera", ""},
                     "names one camera, but the files hold " + std::to_string(imported.size()));
  std::map<std::string, std::string> taken;  // camera name -> where it came from
  for (auto& [path, ic] : imported) {
    // A pinhole calibration is the ceiling webcam, a fisheye one the omni camera, unless named.
    const std::string name = !a.camera.empty()                             ? a.camera
                             : ic.camera.model == CameraModelKind::pinhole ? "ceiling_camera"
                                                                           : "omni_camera";
    const std::string from = path + (ic.label.empty() ? "" : " (" + ic.label + ")");
    if (!taken.emplace(name, from).second)
      throw InputError({path, ic.label, ""}, "both this and " + taken[name] + " would be " + name +
                                                 ": import them one at a time with --camera");
    CameraDescription* target = nullptr;
    for (auto& c : robot.cameras)
      if (c.name == name) target = &c;
    if (!target)
      throw InputError({a.robot, "cameras", name},
                       "no camera '" + name + "' to take " + from +
                           " (a calibration does not know the mount): add it, or name another "
                           "with --camera");
    if (name == "ceiling_camera" && !vision::PinholeCamera::takes(ic.camera.model))
      throw InputError({path, ic.label, "distortion_model"},
                       "the ceiling camera must be a pinhole or kannala_brandt camera (its "
                       "pipeline needs one), this calibration is " +
                           std::string(to_string(ic.camera.model)));
    ic.camera.name = target->name;
    ic.camera.mount = target->mount;
    std::cout << name << ": " << to_string(target->model) << " " << target->width << " x "
              << target->height << " -> " << to_string(ic.camera.model) << " " << ic.camera.width
              << " x " << ic.camera.height << " from " << from << " (" << ic.format << ")\n";
    *target = ic.camera;
  }
  const std::string text = to_robot_json(robot);
  parse_robot_description(text, a.out);  // what is written reads back
  json::write_file(a.out, text);
  std::cout << "wrote " << a.out << "\n";
  return 0;
}

}  // namespace

void add_robot_command(CLI::App& app, Job& run) {
  CLI::App* robot = app.add_subcommand("robot", "Robot descriptions (robot.json)");
  robot->require_subcommand(1);
  auto args = std::make_shared<ImportArgs>();
  CLI::App* imp = robot->add_subcommand(
      "import",
      "Cameras of robot.json from ROS camera_info YAML, Kalibr camchain YAML or OpenCV "
      "calibration files (XML/YAML); wheels and mounts kept from --robot");
  imp->add_option("CALIB", args->calibrations, "Calibration files")->required();
  imp->add_option("--robot", args->robot, "robot.json to update (its wheels and mounts)")
      ->required();
  imp->add_option("-o,--output", args->out, "robot.json to write")->required();
  imp->add_option("--camera", args->camera,
                  "The camera the one calibration is for (default: ceiling_camera for a pinhole, "
                  "omni_camera for a fisheye)");
  imp->callback([args, &run] { run = [args] { return run_import(*args); }; });
}

}  // namespace lampnav::apps
