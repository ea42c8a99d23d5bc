#pragma once
// Mission logs (shared/spec/mission-log.md): one MCAP file of JSON messages on fixed channels, with
// robot.json and map.geojson attached. Each message's `timestamp` is when its data was CAPTURED;
// the MCAP log_time is when it became AVAILABLE to the stack.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/image.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/io/mcap.hpp"

namespace lampnav::io {

namespace topics {
inline constexpr const char* kWheels = "/wheels";
inline constexpr const char* kCeilingImage = "/ceiling_camera/image";
inline constexpr const char* kOmniImage = "/omni_camera/image";
inline constexpr const char* kTruth = "/truth/pose";
inline constexpr const char* kEvents = "/events";
inline constexpr const char* kCommands = "/commands";
}  // namespace topics

struct WheelReading {
  Stamp stamp;
  double left = 0, right = 0;  // m, cumulative wheel travel
};

struct ImageFrame {
  Stamp stamp;
  std::string frame_id;  // "ceiling_camera", "omni_camera"
  std::string format;    // "png" or "jpeg"
  std::string data;      // encoded bytes (base64 only on the wire)
};

struct TruthPose {
  Stamp stamp;
  Pose2 pose;
};

struct MissionEvent {
  Stamp stamp;
  std::string kind;  // "kidnap", "lamp_failure", "frame_drop", ...
  std::string detail;
};

struct CommandMessage {
  Stamp stamp;
  std::string text;
};

// A record of a log with the time it became available.
template <class T>
struct Logged {
  Stamp log_time;
  T value;
};

class MissionLogWriter {
 public:
  MissionLogWriter(const std::string& path, McapWriterOptions options = {});
  ~MissionLogWriter();
  void attach_robot(const std::string& robot_json);
  void attach_map(const std::string& map_geojson);
  void write(Stamp available, const WheelReading& r);
  void write_image(Stamp available, const ImageFrame& f);  // channel chosen by frame_id
  void write(Stamp available, const TruthPose& t);
  void write(Stamp available, const MissionEvent& e);
  void write(Stamp available, const CommandMessage& c);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct MissionLog {
  std::vector<Logged<WheelReading>> wheels;
  std::vector<Logged<ImageFrame>> ceiling_images, omni_images;
  std::vector<Logged<TruthPose>> truth;
  std::vector<Logged<MissionEvent>> events;
  std::vector<Logged<CommandMessage>> commands;
  std::optional<std::string> robot_json, map_geojson;
  McapReadReport report;              // container-level findings (truncation, skipped records)
  std::size_t skipped_messages = 0;   // messages refused for their content (bad JSON, base64, ...)
  std::vector<std::string> problems;  // one line per skipped message, naming topic and sequence
};

// Reads a mission log. Throws InputError for a file that is not MCAP at all; damaged content is
// skipped, counted and reported in the result.
MissionLog read_mission_log(const std::string& path);

// Base64 (RFC 4648, with padding). decode throws std::invalid_argument naming the bad character.
std::string base64_encode(const std::string& bytes);
std::string base64_decode(const std::string& text);

// PNG for grey images (OpenCV's codec, kept out of this header).
std::string encode_png(const Image8& image, int compression = 3);
// Decodes PNG or JPEG bytes to grey (colour is converted); throws InputError(`source`) when the
// bytes are not an image.
Image8 decode_image(const std::string& bytes, const std::string& source);

}  // namespace lampnav::io
