#include "harnesses.hpp"

#include <cstdio>
#include <cstdlib>
#include <optional>

#include "lampnav/core/error.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/io/calibration.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"

namespace lampnav::fuzz {

void broken(const std::string& what) {
  std::fprintf(stderr, "contract broken: %s\n", what.c_str());
  std::abort();
}

namespace {

std::string text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Runs `read` and then `check` on what it gave; the typed errors are the contract's other answer.
template <class Read, class Check>
void contract(Read read, Check check) {
  std::optional<decltype(read())> value;
  try {
    value.emplace(read());
  } catch (const InputError&) {
  } catch (const InputErrors&) {
  } catch (const io::CdrError&) {
  }
  if (value) check(*value);
}

}  // namespace

void map_geojson(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return graph::parse_map(in, "fuzz.geojson"); },
           [](const graph::LoadedMap& m) {
             const std::string once = graph::write_map(m.map);
             const std::string twice =
                 graph::write_map(graph::parse_map(once, "written.geojson").map);
             if (once != twice) broken("a map written and read again differs");
           });
}

void robot_json(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return parse_robot_description(in, "fuzz.json"); },
           [](const RobotDescription& r) {
             const std::string once = to_robot_json(r);
             const std::string twice = to_robot_json(parse_robot_description(once, "written"));
             if (once != twice) broken("a robot.json written and read again differs");
           });
}

void mcap(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return io::read_mcap_bytes(in, "fuzz.mcap"); }, [](const io::McapFile&) {});
}

void mission_log(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return io::parse_mission_log(in, "fuzz.mcap"); },
           [](const io::MissionLog& log) {
             if (log.skipped_messages != log.problems.size())
               broken("skipped messages and their reasons do not match");
           });
}

void route_commands(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return graph::parse_route_commands(in, "fuzz"); },
           [](const std::vector<graph::RouteCommand>& commands) {
             if (commands.empty()) return;
             std::string again;
             for (const auto& c : commands) again += (again.empty() ? "" : ", ") + c.text();
             const auto reparsed = graph::parse_route_commands(again, "written");
             if (reparsed.size() != commands.size())
               broken("commands written and read again: " + again);
             for (std::size_t k = 0; k < commands.size(); ++k)
               if (reparsed[k].text() != commands[k].text())
                 broken("command written and read again differs: " + commands[k].text());
           });
}

void image(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return io::decode_image(in, "fuzz.png"); },
           [](const Image8& img) {
             if (img.width <= 0 || img.height <= 0 ||
                 img.pixels.size() != std::size_t(img.width) * img.height)
               broken("a decoded image's size does not match its pixels");
             const Image8 again = io::decode_image(io::encode_png(img), "written.png");
             if (again.pixels != img.pixels) broken("an image written as PNG and read differs");
           });
}

void ros2_cdr(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::string in = text(data + 1, size - 1);
  switch (data[0] % 10) {
    case 0:
      contract([&] { return io::ros2::compressed_image(in); },
               [](const io::ImageFrame& f) {
                 const auto again = io::ros2::compressed_image(
                     io::ros2::compressed_image_message(f.stamp, f.frame_id, f.format, f.data));
                 if (again.data != f.data || again.stamp != f.stamp) broken("compressed image");
               });
      break;
    case 1:
      contract([&] { return io::ros2::raw_image_grey(in); },
               [](const io::ros2::GreyImage& g) {
                 if (g.image.pixels.size() != std::size_t(g.image.width) * g.image.height)
                   broken("raw image size");
               });
      break;
    case 2:
      contract([&] { return io::ros2::odometry(in); },
               [](const io::OdometryPose& o) {
                 const auto again = io::ros2::odometry(
                     io::ros2::odometry_message(o.stamp, "odom", "base_link", o.pose));
                 if (again.stamp != o.stamp || again.pose.x() != o.pose.x() ||
                     again.pose.y() != o.pose.y())
                   broken("odometry written and read again differs");
               });
      break;
    case 3:
      contract([&] { return io::ros2::wheel_joints(in, "", ""); },
               [](const io::WheelJoints& j) {
                 const auto again = io::ros2::wheel_joints(
                     io::ros2::joint_state_message(j.stamp, {"left_wheel", "right_wheel"},
                                                   {j.left, j.right}),
                     "", "");
                 if (again.left != j.left || again.right != j.right) broken("joint states");
               });
      break;
    case 4:
      contract([&] { return io::ros2::camera_info(in); },
               [](const io::CameraInfo& info) {
                 // The camera it describes: read, or refused as bad input.
                 try {
                   if (const auto c = io::camera_from_info(info, "fuzz"))
                     if (c->width != info.width || c->height != info.height)
                       broken("a CameraInfo's camera is not its size");
                 } catch (const InputError&) {
                 }
               });
      break;
    case 5:
      contract([&] { return io::ros2::string_data(in); },
               [](const std::string& s) {
                 if (s.find('\0') == std::string::npos &&
                     io::ros2::string_data(io::ros2::string_message(s)) != s)
                   broken("string written and read again differs");
               });
      break;
    case 6:
      contract([&] { return io::ros2::tf_transforms(in); },
               [](const std::vector<io::FrameTransform>& t) {
                 const auto again = io::ros2::tf_transforms(io::ros2::tf_message(t));
                 if (again.size() != t.size()) broken("transforms written and read again differ");
                 for (std::size_t k = 0; k < t.size(); ++k)
                   if (again[k].child != t[k].child || again[k].parent != t[k].parent ||
                       again[k].translation != t[k].translation ||
                       (again[k].rotation.coeffs() - t[k].rotation.coeffs()).norm() > 1e-12)
                     broken("transforms written and read again differ");
               });
      break;
    case 9:
      contract([&] { return io::ros2::message_header(in); }, [](const auto&) {});
      break;
    case 8:
      contract([&] { return io::ros2::pose_estimate(in); },
               [](const io::ros2::PoseEstimate& e) {
                 const auto again = io::ros2::pose_estimate(io::ros2::pose_with_covariance_stamped(
                     e.stamp, e.frame_id, e.pose, e.covariance));
                 if (again.stamp != e.stamp || again.pose.x() != e.pose.x() ||
                     again.pose.y() != e.pose.y() || again.covariance != e.covariance)
                   broken("pose estimate written and read again differs");
               });
      break;
    default:
      contract([&] { return io::ros2::raw_image(in); }, [](const io::ImageFrame&) {});
  }
}

void calibration(const std::uint8_t* data, std::size_t size) {
  const std::string in = text(data, size);
  contract([&] { return io::parse_calibration(in, "fuzz.yaml"); },
           [](const std::vector<io::ImportedCamera>&) {});
}

}  // namespace lampnav::fuzz
