#include "lampnav/io/mission_log.hpp"

#include "foxglove_schemas.hpp"
#include "ros2_bag.hpp"
#include "rosbag2_storage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "lampnav/core/error.hpp"
#include "lampnav/core/parallel.hpp"

namespace lampnav::io {

using Json = nlohmann::ordered_json;

// ---------------------------------------------------------------------------------------------
// Base64 and images.

namespace {
constexpr char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
}

std::string base64_encode(const std::string& bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kB64[(v >> 18) & 63];
    out += kB64[(v >> 12) & 63];
    out += kB64[(v >> 6) & 63];
    out += kB64[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kB64[(v >> 18) & 63];
    out += kB64[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kB64[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string base64_decode(const std::string& text) {
  static const auto table = [] {
    std::array<int, 256> t{};
    t.fill(-1);
    for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(kB64[i])] = i;
    return t;
  }();
  if (text.size() % 4 != 0)
    throw std::invalid_argument("length " + std::to_string(text.size()) +
                                " is not a multiple of 4");
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=' && i + 4 == text.size() && k >= 2) {
        v[k] = 0;
        ++pad;
        continue;
      }
      if (pad > 0 || table[static_cast<unsigned char>(c)] < 0) {
        const unsigned char u = static_cast<unsigned char>(c);
        char shown[16];
        if (u >= 0x21 && u < 0x7f)
          std::snprintf(shown, sizeof shown, "'%c'", c);
        else
          std::snprintf(shown, sizeof shown, "byte 0x%02x", u);
        throw std::invalid_argument(std::string("bad character ") + shown + " at " +
                                    std::to_string(i + k));
      }
      v[k] = table[static_cast<unsigned char>(c)];
    }
    const unsigned n = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
    out += static_cast<char>((n >> 16) & 0xff);
    if (pad < 2) out += static_cast<char>((n >> 8) & 0xff);
    if (pad < 1) out += static_cast<char>(n & 0xff);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Writer.

namespace {

Json stamp_json(Stamp t) {
  const std::int64_t ns = to_nanoseconds(t);
  if (ns < 0)
    throw InputError({"", "mission log", "timestamp"},
                     "a time before 1970 (" + std::to_string(ns) +
                         " ns) cannot be written: Foxglove's time is unsigned");
  std::int64_t sec = ns / 1'000'000'000;
  std::int64_t nsec = ns % 1'000'000'000;
  if (nsec < 0) {
    nsec += 1'000'000'000;
    --sec;
  }
  return Json{{"sec", sec}, {"nsec", nsec}};
}

// Foxglove's time: unsigned seconds and nanoseconds (a negative stamp is refused when writing).
const char* const kTimeSchema =
    R"("timestamp": {"type": "object", "title": "time", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}})";

struct ChannelSpec {
  const char* topic;
  const char* schema_name;
  std::string schema;
};

std::vector<ChannelSpec> channel_specs() {
  const std::string t = kTimeSchema;
  return {
      {topics::kWheels, "lampnav.WheelOdometry",
       R"({"type": "object", "properties": {)" + t +
           R"(, "left": {"type": "number"}, "right": {"type": "number"}}})"},
      {topics::kCeilingImage, "foxglove.CompressedImage", foxglove_schemas::kCompressedImage},
      {topics::kOmniImage, "foxglove.CompressedImage", foxglove_schemas::kCompressedImage},
      {topics::kTruth, "foxglove.PoseInFrame", foxglove_schemas::kPoseInFrame},
      {topics::kEvents, "lampnav.Event",
       R"({"type": "object", "properties": {)" + t +
           R"(, "kind": {"type": "string"}, "detail": {"type": "string"}}})"},
      {topics::kCommands, "lampnav.Command",
       R"({"type": "object", "properties": {)" + t + R"(, "text": {"type": "string"}}})"},
      {topics::kPose, "foxglove.PoseInFrame", foxglove_schemas::kPoseInFrame},
      {topics::kEstimate, "lampnav.PoseEstimate",
       R"({"type": "object", "properties": {)" + t +
           R"(, "x": {"type": "number"}, "y": {"type": "number"}, "yaw": {"type": "number"}, "covariance": {"type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9}, "node": {"type": "string"}, "mode": {"type": "string", "enum": ["tracking", "lost", "relocalized", "ambiguous"]}}})"},
      {topics::kHypotheses, "lampnav.Hypotheses",
       R"({"type": "object", "properties": {)" + t +
           R"(, "mode": {"type": "string", "enum": ["tracking", "lost", "relocalized", "ambiguous"]}, "hypotheses": {"type": "array", "items": {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "yaw": {"type": "number"}, "weight": {"type": "number"}, "node": {"type": "string"}}}}}})"},
      {topics::kLamps, "lampnav.LampObservations",
       R"({"type": "object", "properties": {)" + t +
           R"(, "camera": {"type": "string"}, "lamps": {"type": "array", "items": {"type": "object", "properties": {"u": {"type": "number"}, "v": {"type": "number"}, "orientation": {"type": "number"}, "area": {"type": "number"}, "track": {"type": "integer"}, "label": {"type": "string"}}}}}})"},
      {topics::kScene, "foxglove.SceneUpdate", foxglove_schemas::kSceneUpdate},
      {topics::kLog, "foxglove.Log", foxglove_schemas::kLog},
  };
}

}  // namespace

struct MissionLogWriter::Impl {
  McapWriter w;
  std::map<std::string, std::uint16_t> channels;
  std::map<std::string, std::uint16_t> schemas;
  explicit Impl(const std::string& path, McapWriterOptions o) : w(path, std::move(o)) {}

  std::uint16_t channel(const std::string& topic) {
    auto it = channels.find(topic);
    if (it != channels.end()) return it->second;
    for (const auto& spec : channel_specs()) {
      if (topic != spec.topic) continue;
      auto s = schemas.find(spec.schema_name);
      if (s == schemas.end())
        s = schemas
                .emplace(spec.schema_name,
                         w.add_schema(spec.schema_name, "jsonschema", spec.schema))
                .first;
      return channels[topic] = w.add_channel(s->second, topic, "json");
    }
    throw Error("no mission-log channel for topic " + topic);
  }
  void put(const std::string& topic, Stamp available, Stamp captured, const Json& j) {
    const std::uint16_t ch = channel(topic);
    w.write(ch, static_cast<std::uint64_t>(std::max<std::int64_t>(0, to_nanoseconds(available))),
            static_cast<std::uint64_t>(std::max<std::int64_t>(0, to_nanoseconds(captured))),
            j.dump());
  }
};

namespace {

Json pose_json(const Pose2& p) {
  const double h = p.yaw() / 2;
  return {{"position", {{"x", p.x()}, {"y", p.y()}, {"z", 0.0}}},
          {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(h)}, {"w", std::cos(h)}}}};
}

Json color_json(const SceneColor& c) { return {{"r", c.r}, {"g", c.g}, {"b", c.b}, {"a", c.a}}; }

Json point_json(const Eigen::Vector3d& p) { return {{"x", p.x()}, {"y", p.y()}, {"z", p.z()}}; }

Json identity_pose_json() { return pose_json(Pose2()); }

}  // namespace

MissionLogWriter::MissionLogWriter(const std::string& path, McapWriterOptions options)
    : impl_(std::make_unique<Impl>(path, std::move(options))) {}
MissionLogWriter::~MissionLogWriter() = default;

void MissionLogWriter::attach_robot(const std::string& robot_json) {
  impl_->w.attach({0, 0, "robot.json", "application/json", robot_json});
}
void MissionLogWriter::attach_map(const std::string& map_geojson) {
  impl_->w.attach({0, 0, "map.geojson", "application/geo+json", map_geojson});
}
void MissionLogWriter::write(Stamp available, const WheelReading& r) {
  impl_->put(topics::kWheels, available, r.stamp,
             Json{{"timestamp", stamp_json(r.stamp)}, {"left", r.left}, {"right", r.right}});
}
void MissionLogWriter::write_image(Stamp available, const ImageFrame& f) {
  const std::string topic =
      f.frame_id == "omni_camera" ? topics::kOmniImage : topics::kCeilingImage;
  impl_->put(topic, available, f.stamp,
             Json{{"timestamp", stamp_json(f.stamp)},
                  {"frame_id", f.frame_id},
                  {"format", f.format == "jpg" ? std::string("jpeg") : f.format},
                  {"data", base64_encode(f.data)}});
}
void MissionLogWriter::write(Stamp available, const PoseEstimate& e) {
  impl_->put(
      topics::kPose, available, e.stamp,
      Json{{"timestamp", stamp_json(e.stamp)}, {"frame_id", "map"}, {"pose", pose_json(e.pose)}});
  Json cov = Json::array();
  for (double c : e.covariance) cov.push_back(c);
  impl_->put(topics::kEstimate, available, e.stamp,
             Json{{"timestamp", stamp_json(e.stamp)},
                  {"x", e.pose.x()},
                  {"y", e.pose.y()},
                  {"yaw", e.pose.yaw()},
                  {"covariance", cov},
                  {"node", e.node},  // "" in no region: Foxglove parses no type unions
                  {"mode", to_string(e.mode)}});
}

void MissionLogWriter::write(Stamp available, const LampObservations& o) {
  Json lamps = Json::array();
  for (const auto& l : o.lamps)
    lamps.push_back({{"u", l.u},
                     {"v", l.v},
                     {"orientation", l.orientation},
                     {"area", l.area},
                     {"track", l.track},
                     {"label", l.label.value_or("")}});  // "" unlabelled
  impl_->put(topics::kLamps, available, o.stamp,
             Json{{"timestamp", stamp_json(o.stamp)}, {"camera", o.camera}, {"lamps", lamps}});
}

void MissionLogWriter::write(Stamp available, const Hypotheses& h) {
  Json list = Json::array();
  for (const auto& e : h.hypotheses)
    list.push_back({{"x", e.pose.x()},
                    {"y", e.pose.y()},
                    {"yaw", e.pose.yaw()},
                    {"weight", e.weight},
                    {"node", e.node}});
  impl_->put(
      topics::kHypotheses, available, h.stamp,
      Json{{"timestamp", stamp_json(h.stamp)}, {"mode", to_string(h.mode)}, {"hypotheses", list}});
}

void MissionLogWriter::write(Stamp available, const LogMessage& m) {
  impl_->put(topics::kLog, available, m.stamp,
             Json{{"timestamp", stamp_json(m.stamp)},
                  {"level", static_cast<int>(m.level)},
                  {"message", m.message},
                  {"name", m.name},
                  {"file", ""},
                  {"line", 0}});
}

void MissionLogWriter::write(Stamp available, const SceneUpdate& u) {
  Json entities = Json::array();
  for (const auto& e : u.entities) {
    Json lines = Json::array(), cubes = Json::array(), texts = Json::array();
    for (const auto& l : e.lines) {
      Json pts = Json::array();
      for (const auto& p : l.points) pts.push_back(point_json(p));
      lines.push_back({{"type", 0},  // LINE_STRIP
                       {"pose", identity_pose_json()},
                       {"thickness", l.thickness},
                       {"scale_invariant", false},
                       {"points", pts},
                       {"color", color_json(l.color)},
                       {"colors", Json::array()},
                       {"indices", Json::array()}});
    }
    for (const auto& c : e.cubes) {
      const double h = c.yaw / 2;
      cubes.push_back(
          {{"pose",
            {{"position", point_json(c.centre)},
             {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(h)}, {"w", std::cos(h)}}}}},
           {"size", point_json(c.size)},
           {"color", color_json(c.color)}});
    }
    for (const auto& t : e.texts) {
      texts.push_back({{"pose",
                        {{"position", point_json(t.at)},
                         {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}},
                       {"billboard", true},
                       {"font_size", t.size},
                       {"scale_invariant", false},
                       {"color", color_json(t.color)},
                       {"text", t.text}});
    }
    entities.push_back({{"timestamp", stamp_json(u.stamp)},
                        {"frame_id", "map"},
                        {"id", e.id},
                        {"lifetime", {{"sec", 0}, {"nsec", 0}}},
                        {"frame_locked", false},
                        {"metadata", Json::array()},
                        {"arrows", Json::array()},
                        {"cubes", cubes},
                        {"spheres", Json::array()},
                        {"cylinders", Json::array()},
                        {"lines", lines},
                        {"triangles", Json::array()},
                        {"texts", texts},
                        {"models", Json::array()}});
  }
  impl_->put(topics::kScene, available, u.stamp,
             Json{{"deletions", Json::array()}, {"entities", entities}});
}

void MissionLogWriter::write(Stamp available, const TruthPose& t) {
  impl_->put(
      topics::kTruth, available, t.stamp,
      Json{{"timestamp", stamp_json(t.stamp)}, {"frame_id", "map"}, {"pose", pose_json(t.pose)}});
}
const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::kidnap:
      return "kidnap";
    case EventKind::lamp_failure:
      return "lamp_failure";
    case EventKind::frame_drop:
      return "frame_drop";
    case EventKind::other:
      return "other";
  }
  return "other";
}

EventKind event_kind(const std::string& word) {
  for (const EventKind k : {EventKind::kidnap, EventKind::lamp_failure, EventKind::frame_drop})
    if (word == to_string(k)) return k;
  return EventKind::other;
}

void MissionLogWriter::write(Stamp available, const MissionEvent& e) {
  impl_->put(topics::kEvents, available, e.stamp,
             Json{{"timestamp", stamp_json(e.stamp)}, {"kind", e.kind}, {"detail", e.detail}});
}
void MissionLogWriter::write(Stamp available, const CommandMessage& c) {
  impl_->put(topics::kCommands, available, c.stamp,
             Json{{"timestamp", stamp_json(c.stamp)}, {"text", c.text}});
}
void MissionLogWriter::close() { impl_->w.close(); }

// ---------------------------------------------------------------------------------------------
// Reader.

namespace {

struct BadMessage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

const Json& member(const Json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end()) throw BadMessage(std::string("missing \"") + key + "\"");
  return *it;
}
double number(const Json& j, const char* key) {
  const Json& v = member(j, key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw BadMessage(std::string("\"") + key + "\" is not a finite number");
  return v.get<double>();
}
std::string text(const Json& j, const char* key) {
  const Json& v = member(j, key);
  if (!v.is_string()) throw BadMessage(std::string("\"") + key + "\" is not a string");
  return v.get<std::string>();
}
Stamp stamp(const Json& j) {
  const Json& t = member(j, "timestamp");
  const Json& s = member(t, "sec");
  const Json& n = member(t, "nsec");
  if (!s.is_number_integer() || !n.is_number_integer())
    throw BadMessage("timestamp sec/nsec must be integers");
  const std::int64_t nsec = n.get<std::int64_t>();
  if (nsec < 0 || nsec >= 1'000'000'000) throw BadMessage("timestamp nsec must be in [0, 1e9)");
  // Nanoseconds since 1970 in 64 bits reach the year 2262: seconds beyond would wrap.
  constexpr std::int64_t kMaxSec = std::numeric_limits<std::int64_t>::max() / 1'000'000'000 - 1;
  if (s.is_number_unsigned() ? s.get<std::uint64_t>() > std::uint64_t(kMaxSec)
                             : s.get<std::int64_t>() > kMaxSec || s.get<std::int64_t>() < -kMaxSec)
    throw BadMessage("timestamp sec is out of range (more than 292 years from 1970)");
  return stamp_from_nanoseconds(s.get<std::int64_t>() * 1'000'000'000 + nsec);
}
ImageFrame image(const Json& j) {
  ImageFrame f;
  f.stamp = stamp(j);
  f.frame_id = text(j, "frame_id");
  f.format = text(j, "format");
  if (f.format != "png" && f.format != "jpeg" && f.format != "jpg")
    throw BadMessage("image format \"" + f.format + "\" is not png or jpeg");
  try {
    f.data = base64_decode(text(j, "data"));
  } catch (const std::invalid_argument& e) {
    throw BadMessage(std::string("\"data\" is not base64: ") + e.what());
  }
  return f;
}

// One message of lampnav's own JSON channels.
void decode_json(const McapChannel& ch, const McapMessage& m, DecodedMessage& d) {
  using Kind = DecodedMessage::Kind;
  const std::string& topic = ch.topic;
  const bool input = topic == topics::kWheels || topic == topics::kCeilingImage ||
                     topic == topics::kOmniImage || topic == topics::kTruth ||
                     topic == topics::kEvents || topic == topics::kCommands;
  // Other topics (a replay's own outputs, a user's extras) are not inputs: left alone.
  if (!input) return;
  const Stamp avail = stamp_from_nanoseconds(static_cast<std::int64_t>(m.log_time));
  try {
    Json j;
    try {
      j = Json::parse(m.data);
    } catch (const Json::exception& e) {
      // A syntax error, or a number past a double's range ("4E1000000": out_of_range.406).
      throw BadMessage(std::string("bad JSON: ") + e.what());
    }
    if (!j.is_object()) throw BadMessage("not a JSON object");
    if (topic == topics::kWheels) {
      d.wheel = {avail, {stamp(j), number(j, "left"), number(j, "right")}};
      d.kind = Kind::wheels;
    } else if (topic == topics::kCeilingImage || topic == topics::kOmniImage) {
      d.image = {avail, image(j)};
      d.kind = topic == topics::kCeilingImage ? Kind::ceiling : Kind::omni;
    } else if (topic == topics::kTruth) {
      const Json& pose = member(j, "pose");
      const Json& p = member(pose, "position");
      const Json& q = member(pose, "orientation");
      const double yaw = 2.0 * std::atan2(number(q, "z"), number(q, "w"));
      d.truth = {avail, {stamp(j), Pose2(number(p, "x"), number(p, "y"), yaw)}};
      d.kind = Kind::truth;
    } else if (topic == topics::kEvents) {
      d.event = {avail, {stamp(j), text(j, "kind"), j.contains("detail") ? text(j, "detail") : ""}};
      d.kind = Kind::event;
    } else {
      d.command = {avail, {stamp(j), text(j, "text")}};
      d.kind = Kind::command;
    }
  } catch (const BadMessage& e) {
    d.kind = Kind::bad;
    d.problem = skipped(ch, m, e.what());
  }
}

// A decoded message into its place in the log.
void keep(DecodedMessage& d, MissionLog& log) {
  using Kind = DecodedMessage::Kind;
  switch (d.kind) {
    case Kind::wheels:
      log.wheels.push_back(std::move(d.wheel));
      break;
    case Kind::ceiling:
      log.ceiling_images.push_back(std::move(d.image));
      break;
    case Kind::omni:
      log.omni_images.push_back(std::move(d.image));
      break;
    case Kind::truth:
      log.truth.push_back(std::move(d.truth));
      break;
    case Kind::event:
      log.events.push_back(std::move(d.event));
      break;
    case Kind::command:
      log.commands.push_back(std::move(d.command));
      break;
    case Kind::odometry:
      log.odometry.push_back(std::move(d.odometry));
      break;
    case Kind::joints:
      log.wheel_joints.push_back(std::move(d.joints));
      break;
    case Kind::transforms:
      for (auto& t : d.transforms) log.transforms.push_back(std::move(t));
      break;
    case Kind::camera_info:
      log.camera_info[d.topic] = std::move(*d.camera_info);
      break;
    case Kind::bad:
      ++log.skipped_messages;
      log.problems.push_back(std::move(d.problem));
      break;
    case Kind::none:
      break;
  }
}

}  // namespace

MissionLog read_mission_log(const std::string& path, const BagTopics& bag_topics) {
  std::vector<std::string> notes;
  const McapFile f = read_log_container(path, notes);
  MissionLog log = mission_log_of(f, path, bag_topics);
  log.notes.insert(log.notes.begin(), notes.begin(), notes.end());
  return log;
}

MissionLog parse_mission_log(const std::string& bytes, const std::string& source,
                             const BagTopics& bag_topics) {
  return mission_log_of(read_log_bytes(bytes, source), source, bag_topics);
}

MissionLog mission_log_of(const McapFile& f, const std::string& path, const BagTopics& bag_topics) {
  MissionLog log;
  log.report = f.report;
  if (const auto* a = f.attachment("robot.json")) log.robot_json = a->data;
  if (const auto* a = f.attachment("map.geojson")) log.map_geojson = a->data;
  // A ROS 2 bag's input channels are chosen once, before its messages are decoded.
  log.ros2_bag = std::any_of(f.channels.begin(), f.channels.end(),
                             [](const McapChannel& c) { return c.message_encoding == "cdr"; });
  Ros2Channels ros2;
  if (log.ros2_bag) ros2 = choose_ros2_channels(f, path, bag_topics, log.notes);
  // Each message decoded on its own (JSON and base64, or CDR and pixels: most of the time on
  // image logs), on every core, then kept in the file's order.
  std::vector<DecodedMessage> decoded(f.messages.size());
  for_each_index(decoded.size(), [&](std::size_t i) {
    const McapMessage& m = f.messages[i];
    const McapChannel* ch = f.channel(m.channel_id);
    if (!ch) return;
    if (ch->message_encoding == "cdr")
      decode_ros2(ros2, *ch, m, decoded[i]);
    else
      decode_json(*ch, m, decoded[i]);
  });
  for (auto& d : decoded) keep(d, log);
  return log;
}

std::vector<LogInput> inputs_in_arrival_order(const MissionLog& log, bool ceiling, bool omni) {
  using Kind = LogInput::Kind;
  std::vector<LogInput> items;
  for (std::size_t i = 0; i < log.wheels.size(); ++i)
    items.push_back({log.wheels[i].log_time, Kind::wheels, i});
  if (ceiling)
    for (std::size_t i = 0; i < log.ceiling_images.size(); ++i)
      items.push_back({log.ceiling_images[i].log_time, Kind::ceiling, i});
  if (omni)
    for (std::size_t i = 0; i < log.omni_images.size(); ++i)
      items.push_back({log.omni_images[i].log_time, Kind::omni, i});
  std::stable_sort(items.begin(), items.end(), [](const LogInput& a, const LogInput& b) {
    return a.arrival != b.arrival ? a.arrival < b.arrival
                                  : a.kind == Kind::wheels && b.kind != Kind::wheels;
  });
  return items;
}

TruthTrack::TruthTrack(std::vector<Logged<TruthPose>> truth) : truth_(std::move(truth)) {
  std::stable_sort(truth_.begin(), truth_.end(),
                   [](const auto& a, const auto& b) { return a.value.stamp < b.value.stamp; });
}

Pose2 TruthTrack::at(Stamp t) const {
  if (truth_.empty()) return {};
  auto it = std::lower_bound(truth_.begin(), truth_.end(), t,
                             [](const auto& a, Stamp s) { return a.value.stamp < s; });
  if (it == truth_.begin()) return it->value.pose;
  if (it == truth_.end()) return truth_.back().value.pose;
  const auto& b = it->value;
  if (b.stamp == t) return b.pose;
  const auto& a = std::prev(it)->value;
  if ((b.pose.translation() - a.pose.translation()).norm() > 0.5) return a.pose;
  const double f = to_seconds(t - a.stamp) / std::max(1e-12, to_seconds(b.stamp - a.stamp));
  return interpolate(a.pose, b.pose, f);
}

}  // namespace lampnav::io
