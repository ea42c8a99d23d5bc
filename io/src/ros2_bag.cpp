#include "ros2_bag.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cdr.hpp"
#include "lampnav/core/error.hpp"

namespace lampnav::io {

namespace {

// "sensor_msgs/msg/Image" and the older "sensor_msgs/Image" name the same type.
std::string type_of(const McapFile& f, const McapChannel& ch) {
  const McapSchema* s = f.schema(ch.schema_id);
  if (!s) return {};
  std::string name = s->name;
  if (const auto p = name.find("/msg/"); p != std::string::npos) name.erase(p, 4);
  return name;
}

std::string lower(std::string t) {
  for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return t;
}

bool is_image(const std::string& type) {
  return type == "sensor_msgs/CompressedImage" || type == "sensor_msgs/Image";
}

struct Header {
  Stamp stamp;
  std::string frame_id;
  // A frame stamped and named by the header.
  ImageFrame frame() const {
    ImageFrame f;
    f.stamp = stamp;
    f.frame_id = frame_id;
    return f;
  }
};

Header header(CdrReader& r) {
  Header h;
  const std::int32_t sec = r.i32("header.stamp.sec");
  const std::uint32_t nsec = r.u32("header.stamp.nanosec");
  if (nsec >= 1'000'000'000u) throw CdrError("header.stamp.nanosec is not below 1e9");
  if (sec < 0) throw CdrError("header.stamp.sec is negative");
  h.stamp = stamp_from_nanoseconds(std::int64_t(sec) * 1'000'000'000 + nsec);
  h.frame_id = r.string("header.frame_id");
  return h;
}

// sensor_msgs/msg/CompressedImage: the bytes as they are (PNG or JPEG, told by their magic, not
// by the free-text `format`).
ImageFrame compressed_image(const std::string& data) {
  CdrReader r(data);
  ImageFrame f = header(r).frame();
  const std::string format = r.string("format");
  f.data = r.bytes("data");
  const auto* b = reinterpret_cast<const unsigned char*>(f.data.data());
  if (f.data.size() >= 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G')
    f.format = "png";
  else if (f.data.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF)
    f.format = "jpeg";
  else
    throw CdrError("data is neither PNG nor JPEG (format \"" + format + "\")");
  return f;
}

// sensor_msgs/msg/Image: grey from the supported encodings, kept as a fast PNG.
ImageFrame raw_image(const std::string& data) {
  CdrReader r(data);
  ImageFrame f = header(r).frame();
  const std::uint32_t height = r.u32("height"), width = r.u32("width");
  const std::string encoding = r.string("encoding");
  const bool big_endian = r.u8("is_bigendian") != 0;
  const std::uint32_t step = r.u32("step");
  const std::string pixels = r.bytes("data");
  int channels = 0, depth = 1;
  if (encoding == "mono8" || encoding == "8UC1")
    channels = 1;
  else if (encoding == "mono16" || encoding == "16UC1")
    channels = 1, depth = 2;
  else if (encoding == "bgr8" || encoding == "rgb8" || encoding == "8UC3")
    channels = 3;
  else if (encoding == "bgra8" || encoding == "rgba8" || encoding == "8UC4")
    channels = 4;
  else
    throw CdrError("encoding \"" + encoding +
                   "\" is not read (mono8, mono16, bgr8, rgb8, bgra8, rgba8)");
  if (width == 0 || height == 0 || width > 16384 || height > 16384)
    throw CdrError("image size " + std::to_string(width) + " x " + std::to_string(height) +
                   " is out of range");
  const std::uint64_t row = std::uint64_t(width) * channels * depth;
  if (step < row)
    throw CdrError("step " + std::to_string(step) + " is shorter than a row (" +
                   std::to_string(row) + " bytes)");
  if (std::uint64_t(step) * height > pixels.size())
    throw CdrError("data holds " + std::to_string(pixels.size()) + " bytes, step x height is " +
                   std::to_string(std::uint64_t(step) * height));
  const bool rgb = encoding[0] == 'r';
  Image8 grey(static_cast<int>(width), static_cast<int>(height));
  for (std::uint32_t y = 0; y < height; ++y) {
    const auto* in = reinterpret_cast<const unsigned char*>(pixels.data()) + std::size_t(y) * step;
    std::uint8_t* out = &grey.pixels[std::size_t(y) * width];
    for (std::uint32_t x = 0; x < width; ++x) {
      const unsigned char* p = in + std::size_t(x) * channels * depth;
      if (depth == 2) {
        const unsigned v = big_endian ? (p[0] << 8 | p[1]) : (p[1] << 8 | p[0]);
        out[x] = static_cast<std::uint8_t>(v >> 8);
      } else if (channels == 1) {
        out[x] = p[0];
      } else {
        // ITU-R 601 luma, as OpenCV's colour conversion.
        const double b = rgb ? p[2] : p[0], g = p[1], rr = rgb ? p[0] : p[2];
        out[x] = static_cast<std::uint8_t>(std::lround(0.114 * b + 0.587 * g + 0.299 * rr));
      }
    }
  }
  f.format = "png";
  f.data = encode_png(grey, 1);
  return f;
}

OdometryPose odometry(const std::string& data) {
  CdrReader r(data);
  OdometryPose o;
  o.stamp = header(r).stamp;
  r.string("child_frame_id");
  const double x = r.f64("pose.pose.position.x"), y = r.f64("pose.pose.position.y");
  r.f64("pose.pose.position.z");
  const double qx = r.f64("pose.pose.orientation.x"), qy = r.f64("pose.pose.orientation.y"),
               qz = r.f64("pose.pose.orientation.z"), qw = r.f64("pose.pose.orientation.w");
  for (int k = 0; k < 36; ++k) r.f64("pose.covariance");
  for (int k = 0; k < 6 + 36; ++k) r.f64("twist");
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(qx + qy + qz + qw))
    throw CdrError("pose is not finite");
  const double yaw = std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
  o.pose = Pose2(x, y, yaw);
  return o;
}

// sensor_msgs/msg/JointState: the positions of the two wheel joints, found by name.
WheelJoints wheel_joints(const std::string& data, const std::string& left_name,
                         const std::string& right_name) {
  CdrReader r(data);
  WheelJoints w;
  w.stamp = header(r).stamp;
  const std::vector<std::string> names = r.strings("name");
  const std::vector<double> position = r.f64s("position");
  if (position.size() != names.size())
    throw CdrError("position holds " + std::to_string(position.size()) + " values for " +
                   std::to_string(names.size()) + " names");
  // Named, or the one joint whose name holds the side (a "wheel" one before others).
  auto find = [&](const std::string& wanted, const char* side) -> std::size_t {
    std::vector<std::size_t> hits, wheels;
    for (std::size_t k = 0; k < names.size(); ++k) {
      const bool hit =
          !wanted.empty() ? names[k] == wanted : lower(names[k]).find(side) != std::string::npos;
      if (!hit) continue;
      hits.push_back(k);
      if (lower(names[k]).find("wheel") != std::string::npos) wheels.push_back(k);
    }
    const auto& pick = wheels.size() == 1 ? wheels : hits;
    if (pick.size() != 1) {
      std::string all;
      for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
      throw CdrError(std::string("no single ") + side + " wheel joint among: " + all +
                     " (name it with --" + side + "-joint)");
    }
    return pick.front();
  };
  const std::size_t l = find(left_name, "left"), rr = find(right_name, "right");
  w.left = position[l];
  w.right = position[rr];
  if (!std::isfinite(w.left) || !std::isfinite(w.right))
    throw CdrError("a wheel position is not finite");
  return w;
}

CameraInfo camera_info(const std::string& data) {
  CdrReader r(data);
  CameraInfo c;
  const Header h = header(r);
  c.stamp = h.stamp;
  c.frame_id = h.frame_id;
  c.height = static_cast<int>(r.u32("height"));
  c.width = static_cast<int>(r.u32("width"));
  c.distortion_model = r.string("distortion_model");
  c.d = r.f64s("d");
  for (auto& v : c.k) v = r.f64("k");
  for (int k = 0; k < 9; ++k) r.f64("r");
  for (auto& v : c.p) v = r.f64("p");
  return c;
}

std::string topic_list(const McapFile& f, const std::vector<std::size_t>& counts) {
  std::ostringstream s;
  bool first = true;
  for (const auto& ch : f.channels) {
    s << (first ? "" : ", ") << ch.topic << " (" << type_of(f, ch) << ", "
      << counts[std::size_t(&ch - f.channels.data())] << " messages)";
    first = false;
  }
  return s.str();
}

}  // namespace

Ros2Channels choose_ros2_channels(const McapFile& f, const std::string& path,
                                  const BagTopics& wanted, std::vector<std::string>& notes) {
  Ros2Channels c;
  c.left_joint = wanted.left_joint;
  c.right_joint = wanted.right_joint;
  for (const auto& ch : f.channels)
    if (ch.message_encoding == "cdr") c.types[ch.id] = type_of(f, ch);
  auto type = [&](const McapChannel& ch) -> std::string {
    const auto it = c.types.find(ch.id);
    return it == c.types.end() ? std::string() : it->second;
  };
  std::vector<std::size_t> counts(f.channels.size(), 0);
  std::map<std::uint16_t, std::size_t> index;
  for (std::size_t k = 0; k < f.channels.size(); ++k) index[f.channels[k].id] = k;
  for (const auto& m : f.messages)
    if (const auto it = index.find(m.channel_id); it != index.end()) ++counts[it->second];
  auto fail = [&](const std::string& field, const std::string& what) {
    throw InputError({path, "topics", field}, what + "; the bag has: " + topic_list(f, counts));
  };
  // The channel of a topic given by name: it must be there, with a type that fits.
  auto named = [&](const std::string& topic, const char* field, auto fits) -> const McapChannel* {
    const McapChannel* ch = f.channel(topic);
    if (!ch || type(*ch).empty()) fail(field, "no CDR topic \"" + topic + "\"");
    if (!fits(type(*ch)))
      fail(field, "\"" + topic + "\" is a " + type(*ch) + ", not what " + field + " needs");
    return ch;
  };
  // Guessed: the image topics whose name says the camera, a compressed one before a raw one.
  auto guess_camera = [&](std::initializer_list<const char*> words) -> const McapChannel* {
    std::vector<const McapChannel*> found, compressed;
    for (const auto& ch : f.channels) {
      if (!is_image(type(ch))) continue;
      const std::string t = lower(ch.topic);
      if (std::none_of(words.begin(), words.end(),
                       [&](const char* w) { return t.find(w) != std::string::npos; }))
        continue;
      found.push_back(&ch);
      if (type(ch) == "sensor_msgs/CompressedImage") compressed.push_back(&ch);
    }
    const auto& pick = compressed.empty() ? found : compressed;
    return pick.size() == 1 ? pick.front() : nullptr;
  };
  // The one channel of a type, or among several the one with the usual name.
  auto only = [&](const char* of_type, const std::string& usual, const char* field,
                  const std::string& several) -> const McapChannel* {
    std::vector<const McapChannel*> all;
    for (const auto& ch : f.channels)
      if (type(ch) == of_type) all.push_back(&ch);
    if (all.size() == 1) return all.front();
    for (const auto* ch : all)
      if (ch->topic == usual || "/" + ch->topic == usual) return ch;
    if (all.size() > 1) fail(field, several);
    return nullptr;
  };

  if (!wanted.ceiling_image.empty())
    c.ceiling = named(wanted.ceiling_image, "ceiling camera topic", is_image);
  else if ((c.ceiling = guess_camera({"ceiling"})))
    notes.push_back("ceiling camera images from " + c.ceiling->topic + " (by its name)");
  if (!wanted.omni_image.empty())
    c.omni = named(wanted.omni_image, "omni camera topic", is_image);
  else if ((c.omni = guess_camera({"omni", "fisheye", "panoram", "360"})))
    notes.push_back("omni camera images from " + c.omni->topic + " (by its name)");
  auto is_odometry = [](const std::string& t) { return t == "nav_msgs/Odometry"; };
  auto is_joint_state = [](const std::string& t) { return t == "sensor_msgs/JointState"; };
  if (!wanted.odometry.empty()) {
    c.odometry = named(wanted.odometry, "odometry topic", is_odometry);
  } else if (!wanted.joint_states.empty()) {
    c.joints = named(wanted.joint_states, "joint states topic", is_joint_state);
  } else {
    c.odometry = only("nav_msgs/Odometry", "/odom", "odometry topic",
                      "several nav_msgs/msg/Odometry topics; name one with --odometry-topic");
    if (!c.odometry)
      c.joints = only("sensor_msgs/JointState", "/joint_states", "joint states topic",
                      "no odometry, and several sensor_msgs/msg/JointState topics; name one with "
                      "--joint-states-topic");
  }
  const bool images =
      std::any_of(c.types.begin(), c.types.end(), [](const auto& t) { return is_image(t.second); });
  if (images && !c.ceiling && !c.omni)
    fail("camera topics",
         "cannot tell which image topic is which camera (no name says \"ceiling\", \"omni\" or "
         "\"fisheye\"); name them with --ceiling-topic and --omni-topic");
  if (c.ceiling && c.ceiling == c.omni)
    fail("camera topics", "the ceiling and omni cameras cannot both be " + c.ceiling->topic);

  if (c.odometry)
    notes.push_back("wheel odometry from " + c.odometry->topic);
  else if (c.joints)
    notes.push_back("wheel odometry from the wheel joints of " + c.joints->topic);
  else
    notes.push_back(
        "no nav_msgs/msg/Odometry or sensor_msgs/msg/JointState topic: the bag gives no wheel "
        "odometry");
  return c;
}

void decode_ros2(const Ros2Channels& c, const McapChannel& ch, const McapMessage& m,
                 DecodedMessage& d) {
  using Kind = DecodedMessage::Kind;
  const auto it = c.types.find(ch.id);
  if (it == c.types.end()) return;
  const std::string& type = it->second;
  const Stamp avail = stamp_from_nanoseconds(static_cast<std::int64_t>(m.log_time));
  try {
    if (&ch == c.ceiling || &ch == c.omni) {
      d.image = {avail, type == "sensor_msgs/Image" ? raw_image(m.data) : compressed_image(m.data)};
      if (d.image.value.frame_id.empty())
        d.image.value.frame_id = &ch == c.ceiling ? "ceiling_camera" : "omni_camera";
      d.kind = &ch == c.ceiling ? Kind::ceiling : Kind::omni;
    } else if (&ch == c.odometry) {
      d.odometry = {avail, odometry(m.data)};
      d.kind = Kind::odometry;
    } else if (&ch == c.joints) {
      d.joints = {avail, wheel_joints(m.data, c.left_joint, c.right_joint)};
      d.kind = Kind::joints;
    } else if (type == "sensor_msgs/CameraInfo") {
      d.camera_info = std::make_unique<CameraInfo>(camera_info(m.data));
      d.topic = ch.topic;
      d.kind = Kind::camera_info;
    }
  } catch (const CdrError& e) {
    d.kind = Kind::bad;
    d.problem = skipped(ch, m, e.what(), type);
  } catch (const InputError& e) {
    d.kind = Kind::bad;
    d.problem = skipped(ch, m, e.what());
  }
}

namespace {

// A copy of a bag's readings in capture order.
template <class T>
std::vector<Logged<T>> by_capture(std::vector<Logged<T>> v) {
  std::stable_sort(v.begin(), v.end(),
                   [](const auto& a, const auto& b) { return a.value.stamp < b.value.stamp; });
  return v;
}

}  // namespace

void wheels_from_odometry(MissionLog& log, double semi_axis) {
  if (!log.wheels.empty() || log.odometry.size() < 2) return;
  const auto odo = by_capture(log.odometry);
  double left = 0, right = 0;
  log.wheels.push_back({odo.front().log_time, {odo.front().value.stamp, 0.0, 0.0}});
  for (std::size_t k = 1; k < odo.size(); ++k) {
    if (!(odo[k].value.stamp > odo[k - 1].value.stamp)) continue;
    const Pose2 step = odo[k - 1].value.pose.between(odo[k].value.pose);
    // A differential drive moves along its heading: the chord of the step (forwards or
    // backwards), and its turn. The chord is the travel for odometry integrated by the midpoint
    // rule (ROS's diff_drive_controller), and within ds dyaw^2 / 24 of it for exact arcs.
    const double dyaw = step.yaw();
    const double ds = std::copysign(step.translation().norm(), step.x());
    left += ds - semi_axis * dyaw;
    right += ds + semi_axis * dyaw;
    log.wheels.push_back({odo[k].log_time, {odo[k].value.stamp, left, right}});
  }
}

void wheels_from_joints(MissionLog& log, double wheel_radius) {
  if (!log.wheels.empty() || log.wheel_joints.empty()) return;
  const auto joints = by_capture(log.wheel_joints);
  const double l0 = joints.front().value.left, r0 = joints.front().value.right;
  Stamp last;
  for (const auto& j : joints) {
    if (!log.wheels.empty() && !(j.value.stamp > last)) continue;
    last = j.value.stamp;
    log.wheels.push_back(
        {j.log_time,
         {j.value.stamp, wheel_radius * (j.value.left - l0), wheel_radius * (j.value.right - r0)}});
  }
}

}  // namespace lampnav::io
