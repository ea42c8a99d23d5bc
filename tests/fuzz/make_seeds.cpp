// Writes the fuzzers' seed corpora that are not copies of files in the tree (tests/fuzz/corpus/):
// small mission logs in each container form (zstd chunks, uncompressed, unchunked, no summary,
// cut short), a ROS 2 bag in MCAP and in rosbag2's SQLite, one CDR message of each type the node
// and the bag reader take, tiny images, route commands, calibrations and robots. Run once when a
// reader changes:
//   build/tests/fuzz/lampnav_make_seeds tests/fuzz/corpus
// The bundled maps and fixtures are copied beside them by the same program.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>

#include "cdr.hpp"  // io's CDR writer, for messages the library has no encoder of
#include "lampnav/core/robot_description.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "rosbag2_writer.hpp"  // tests/support

using namespace lampnav;
namespace fs = std::filesystem;

namespace {

fs::path out;

void put(const std::string& harness, const std::string& name, const std::string& bytes) {
  fs::create_directories(out / harness);
  std::ofstream(out / harness / name, std::ios::binary) << bytes;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

Stamp ms(int k) { return stamp_from_nanoseconds(std::int64_t(k) * 1'000'000); }

Image8 tiny(int w, int h) {
  Image8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) = static_cast<std::uint8_t>(
          (x - w / 2) * (x - w / 2) + (y - h / 2) * (y - h / 2) < 9 ? 250 : 20);
  return img;
}

std::string log_bytes(const std::string& robot, io::McapWriterOptions o) {
  const fs::path tmp = fs::temp_directory_path() / "lampnav_seed.mcap";
  {
    io::MissionLogWriter w(tmp.string(), o);
    w.attach_robot(robot);
    for (int k = 0; k < 5; ++k)
      w.write(ms(10 * k), io::WheelReading{ms(10 * k), 0.01 * k, 0.012 * k});
    w.write_image(ms(45), {ms(40), "ceiling_camera", "png", io::encode_png(tiny(12, 10))});
    w.write_image(ms(48), {ms(40), "omni_camera", "jpeg", io::encode_jpeg(tiny(16, 16), 80)});
    w.write(ms(20), io::TruthPose{ms(20), Pose2(1, 2, 0.5)});
    w.write(ms(30), io::MissionEvent{ms(30), io::EventKind::kidnap, "to C3"});
    w.write(ms(31), io::CommandMessage{ms(31), "go to J2"});
    w.close();
  }
  std::string b = slurp(tmp);
  fs::remove(tmp);
  return b;
}

std::string bag_bytes() {
  const fs::path tmp = fs::temp_directory_path() / "lampnav_seed_bag.mcap";
  {
    io::McapWriter w(tmp.string(), {"ros2"});
    auto channel = [&](const char* type, const char* topic) {
      return w.add_channel(w.add_schema(type, "ros2msg", std::string("# ") + type + "\n"), topic,
                           "cdr");
    };
    const auto odom = channel("nav_msgs/msg/Odometry", "/odom");
    const auto image =
        channel("sensor_msgs/msg/CompressedImage", "/ceiling_camera/image/compressed");
    const auto tf = channel("tf2_msgs/msg/TFMessage", "/tf_static");
    const auto joints = channel("sensor_msgs/msg/JointState", "/joint_states");
    for (int k = 0; k < 4; ++k) {
      const std::uint64_t t = 10'000'000ULL * k;
      w.write(
          odom, t, t,
          io::ros2::odometry_message(ms(10 * k), "odom", "base_link", Pose2(0.1 * k, 0, 0.05 * k)));
      w.write(joints, t, t,
              io::ros2::joint_state_message(ms(10 * k), {"left_wheel", "right_wheel"},
                                            {k * 0.1, k * 0.12}));
    }
    w.write(image, 25'000'000, 25'000'000,
            io::ros2::compressed_image_message(ms(20), "ceiling_camera", "png",
                                               io::encode_png(tiny(12, 10))));
    w.write(tf, 1, 1,
            io::ros2::tf_message({{ms(0), "base_link", "ceiling_camera", Pose2(0.1, 0, 0)}}));
    w.close();
  }
  std::string b = slurp(tmp);
  fs::remove(tmp);
  return b;
}

// The same bag in rosbag2's sqlite3 storage, its images compressed message by message.
std::string db3_bytes() {
  const io::McapFile bag = io::read_mcap_bytes(bag_bytes(), "bag");
  const fs::path tmp = fs::temp_directory_path() / "lampnav_seed_bag.db3";
  fs::remove(tmp);
  {
    test::Rosbag2SqliteWriter w(tmp.string());
    w.copy(bag, 0, bag.messages.size(), [&](const io::McapMessage& m) {
      return bag.channel(m.channel_id)->topic.find("image") != std::string::npos;
    });
  }
  std::string b = slurp(tmp);
  fs::remove(tmp);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: lampnav_make_seeds CORPUS_DIR\n";
    return 2;
  }
  out = argv[1];
  const fs::path src = LAMPNAV_SOURCE_DIR;

  // Maps: the bundled ones, the fixtures, Nav2's sample graph.
  for (const auto& p : {src / "maps/office_floor.geojson", src / "maps/domus_museum.geojson",
                        src / "tests/fixtures/nav2/sample_graph.geojson"})
    put("map_geojson", p.filename().string(), slurp(p));
  for (const auto& e : fs::directory_iterator(src / "tests/fixtures/maps"))
    put("map_geojson", e.path().filename().string(), slurp(e.path()));

  // Robots: the bundled one and one with each fisheye model.
  const std::string pioneer = slurp(src / "maps/robots/pioneer.json");
  put("robot_json", "pioneer.json", pioneer);
  RobotDescription kb = parse_robot_description(pioneer, "pioneer.json");
  for (auto& c : kb.cameras)
    if (c.name == "omni_camera") {
      c.model = CameraModelKind::kannala_brandt;
      c.fisheye.f = 402.1;
      c.fisheye.beta = 0.999;
      c.fisheye.k = {0.034, -0.0041, 0.00062, -0.00009};
      c.fisheye.fov_deg = 180;
    }
  put("robot_json", "kannala_brandt.json", to_robot_json(kb));

  // Logs and containers.
  io::McapWriterOptions zstd, plain, unchunked, no_summary;
  plain.compression = io::McapCompression::none;
  unchunked.chunked = false;
  no_summary.summary = false;
  const std::string log = log_bytes(pioneer, zstd);
  for (const char* h : {"mission_log", "mcap"}) {
    put(h, "log_zstd.mcap", log);
    put(h, "log_plain.mcap", log_bytes(pioneer, plain));
    put(h, "log_unchunked.mcap", log_bytes(pioneer, unchunked));
    put(h, "log_no_summary.mcap", log_bytes(pioneer, no_summary));
    put(h, "log_cut.mcap", log.substr(0, log.size() * 2 / 3));
    put(h, "bag.mcap", bag_bytes());
  }
  // ROS 2 bags in rosbag2's sqlite3 storage: one made here, and one rosbag2 itself wrote.
  put("mission_log", "bag.db3", db3_bytes());
  put("mission_log", "talker.db3", slurp(src / "tests/fixtures/rosbag2/talker/talker.db3"));

  // CDR messages: the first byte picks the decoder (harnesses.cpp).
  const Stamp t = ms(1500);
  auto cdr = [&](int selector, const std::string& name, const std::string& bytes) {
    put("ros2_cdr", name, std::string(1, static_cast<char>(selector)) + bytes);
  };
  cdr(0, "compressed_image",
      io::ros2::compressed_image_message(t, "cam", "png", io::encode_png(tiny(6, 5))));
  io::CdrWriter raw;
  raw.header(1'000, "cam")
      .u32(2)
      .u32(3)
      .string("bgr8")
      .u8(0)
      .u32(10)
      .bytes(std::string(20, '\x40'));
  cdr(1, "raw_image", raw.data());
  io::CdrWriter yuyv;  // packed YUV 4:2:2 from a webcam
  yuyv.header(1'000, "cam").u32(3).u32(4).string("yuyv").u8(0).u32(8).bytes(std::string(24, 'y'));
  cdr(1, "raw_image_yuyv", yuyv.data());
  io::CdrWriter bayer;  // a 16-bit mosaic, big endian
  bayer.header(1'000, "cam")
      .u32(4)
      .u32(4)
      .string("bayer_grbg16")
      .u8(1)
      .u32(8)
      .bytes(std::string(32, '\x21'));
  cdr(1, "raw_image_bayer16", bayer.data());
  cdr(2, "odometry", io::ros2::odometry_message(t, "odom", "base_link", Pose2(1, -2, 0.3)));
  cdr(3, "joint_state",
      io::ros2::joint_state_message(t, {"left_wheel", "right_wheel"}, {1.5, -0.5}));
  io::CdrWriter info;
  info.header(1'000, "cam").u32(240).u32(320).string("plumb_bob").f64s({-0.1, 0.01, 0, 0, 0});
  for (int k = 0; k < 9 + 9 + 12; ++k) info.f64(k % 4 == 0 ? 300 : 0.5);
  info.u32(1).u32(1).u32(0).u32(0).u32(0).u32(0).u8(0);
  cdr(4, "camera_info", info.data());
  cdr(5, "string", io::ros2::string_message("follow the corridor"));
  cdr(6, "tf", io::ros2::tf_message({{t, "base_link", "cam", Pose2(0.1, 0.2, 0.3)}}));
  cdr(7, "raw_image_mono16", raw.data());
  cdr(8, "pose_estimate",
      io::ros2::pose_with_covariance_stamped(t, "map", Pose2(3.5, -1.25, 0.4),
                                             Eigen::Vector3d(0.25, 0.25, 0.0685).asDiagonal()));
  cdr(9, "message_header",
      io::ros2::compressed_image_message(t, "ceiling_optical", "png", std::string(8, '\x89')));

  // Images.
  put("image", "tiny.png", io::encode_png(tiny(12, 10)));
  put("image", "tiny.jpg", io::encode_jpeg(tiny(16, 16), 75));

  // Route commands.
  int n = 0;
  for (const char* c :
       {"follow the corridor and turn right at the first corner", "go to J2",
        "follow corridor C1, stop at door \"Lab 3\"", "turn left at the 21st junction",
        "enter hall H1, go to Workshop", "follow the corridor, turn left at the 3rd corner"})
    put("route_commands", "command" + std::to_string(++n) + ".txt", c);

  // Calibrations.
  put("calibration", "camera_info.yaml",
      "image_width: 640\nimage_height: 480\ncamera_name: webcam\ncamera_matrix:\n  rows: 3\n  "
      "cols: 3\n"
      "  data: [612.3, 0, 318.2, 0, 610.8, 241.7, 0, 0, 1]\ndistortion_model: plumb_bob\n"
      "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.112, 0.071, 0.0012, -0.0007, "
      "-0.013]\n");
  put("calibration", "equidistant.yaml",
      "image_width: 1280\nimage_height: 1024\ncamera_name: omni\ncamera_matrix: {rows: 3, cols: 3, "
      "data: [402.1, 0, 641.3, 0, 401.7, 509.2, 0, 0, 1]}\ndistortion_model: equidistant\n"
      "distortion_coefficients: {rows: 1, cols: 4, data: [0.034, -0.0041, 0.00062, -0.00009]}\n");
  put("calibration", "camchain.yaml",
      "cam0:\n  camera_model: pinhole\n  distortion_coeffs: [-0.29, 0.08, 0.00019, 1.9e-05]\n"
      "  distortion_model: radtan\n  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
      "  resolution: [752, 480]\n  rostopic: /ceiling/image_raw\n");
  put("calibration", "opencv.xml",
      "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>320</image_width>\n"
      "<image_height>240</image_height>\n<camera_matrix type_id=\"opencv-matrix\"><rows>3</rows>"
      "<cols>3</cols><dt>d</dt><data>300. 0. 160. 0. 300. 120. 0. 0. 1.</data></camera_matrix>\n"
      "<distortion_coefficients type_id=\"opencv-matrix\"><rows>5</rows><cols>1</cols><dt>d</dt>"
      "<data>-0.1 0.01 0. 0. 0.</data></distortion_coefficients>\n</opencv_storage>\n");
  put("calibration", "opencv.yaml",
      "%YAML:1.0\n---\nimage_width: 320\nimage_height: 240\ncamera_matrix: !!opencv-matrix\n"
      "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 300., 0., 160., 0., 300., 120., 0., 0., 1. ]\n"
      "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
      "   data: [ -0.1, 0.01, 0., 0., 0. ]\n");
  std::cout << "seeds written to " << out << "\n";
  return 0;
}
