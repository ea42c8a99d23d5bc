#pragma once
// Camera calibrations from the usual tools, as robot.json cameras (conventions.md):
//  - ROS camera_info YAML (camera_calibration, camera_info_manager): distortion_model plumb_bob
//    (pinhole, k1 k2 p1 p2 k3) or equidistant (kannala_brandt, k1..k4);
//  - Kalibr camchain YAML (cam0, cam1, ...): camera_model pinhole with distortion_model radtan
//    (pinhole) or equidistant (kannala_brandt);
//  - OpenCV calibration files (XML or YAML from cv::FileStorage, as OpenCV's calibration sample
//    writes them): camera_matrix, distortion_coefficients, image_width, image_height, and
//    fisheye_model (non-zero: kannala_brandt).
// The intrinsics only: a calibration knows neither the camera's mount on the robot nor the
// robot's wheels. Anything else (another distortion model, a rational polynomial with non-zero
// terms, a skewed or non-finite matrix) is refused with InputError naming the file, the camera
// and the field.

#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"

namespace lampnav::io {

struct CameraInfo;

struct ImportedCamera {
  CameraDescription camera;  // name: see `label`; mount left zero
  std::string format;        // "ROS camera_info", "Kalibr camchain", "OpenCV"
  std::string label;         // what the file calls the camera (camera_name, cam0 and its topic)
};

// Reads one calibration file (its format told by its keys).
std::vector<ImportedCamera> read_calibration(const std::string& path);
// The same from the file's text; `source` names it in messages.
std::vector<ImportedCamera> parse_calibration(const std::string& text, const std::string& source);
// The camera a sensor_msgs/msg/CameraInfo describes (a bag's, a live camera's), read as its
// YAML is; nullopt when the driver publishes it uncalibrated (all of K zero). `source` names
// the topic in messages.
std::optional<CameraDescription> camera_from_info(const CameraInfo& info,
                                                  const std::string& source);

}  // namespace lampnav::io
