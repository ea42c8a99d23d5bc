#include "ros2_bag.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "cdr.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/io/ros2_messages.hpp"

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

bool is_image(const std::string& type) {
  return type == "sensor_msgs/CompressedImage" || type == "sensor_msgs/Image";
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
      d.image = {avail, type == "sensor_msgs/Image" ? ros2::raw_image(m.data)
                                                    : ros2::compressed_image(m.data)};
      if (d.image.value.frame_id.empty())
        d.image.value.frame_id = &ch == c.ceiling ? "ceiling_camera" : "omni_camera";
      d.kind = &ch == c.ceiling ? Kind::ceiling : Kind::omni;
    } else if (&ch == c.odometry) {
      d.odometry = {avail, ros2::odometry(m.data)};
      d.kind = Kind::odometry;
    } else if (&ch == c.joints) {
      d.joints = {avail, ros2::wheel_joints(m.data, c.left_joint, c.right_joint)};
      d.kind = Kind::joints;
    } else if (type == "tf2_msgs/TFMessage") {
      d.transforms = ros2::tf_transforms(m.data);
      const bool is_static =
          ch.topic.size() >= 9 && ch.topic.compare(ch.topic.size() - 9, 9, "tf_static") == 0;
      for (auto& t : d.transforms) t.is_static = is_static;
      d.kind = Kind::transforms;
    } else if (type == "sensor_msgs/CameraInfo") {
      d.camera_info = std::make_unique<CameraInfo>(ros2::camera_info(m.data));
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
  ros2::OdometryWheels wheels(semi_axis);
  for (const auto& o : by_capture(log.odometry))
    if (const auto w = wheels.add(o.value)) log.wheels.push_back({o.log_time, *w});
}

void wheels_from_joints(MissionLog& log, double wheel_radius) {
  if (!log.wheels.empty() || log.wheel_joints.empty()) return;
  ros2::JointWheels wheels(wheel_radius);
  for (const auto& j : by_capture(log.wheel_joints))
    if (const auto w = wheels.add(j.value)) log.wheels.push_back({j.log_time, *w});
}

namespace {

// A frame's pose in the root of its tree, the latest transform of each pair.
struct InRoot {
  std::string root;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::vector<std::string> chain;  // the frame, its parent, ..., the root
};

std::optional<InRoot> in_root(const std::map<std::string, const FrameTransform*>& parent_of,
                              const std::string& frame) {
  InRoot r;
  std::string cur = frame;
  r.chain.push_back(cur);
  for (;;) {
    const auto it = parent_of.find(cur);
    if (it == parent_of.end()) break;
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = it->second->rotation.toRotationMatrix();
    t.translation() = it->second->translation;
    r.pose = t * r.pose;
    cur = it->second->parent;
    if (std::find(r.chain.begin(), r.chain.end(), cur) != r.chain.end()) return std::nullopt;
    r.chain.push_back(cur);
  }
  r.root = cur;
  return r;
}

}  // namespace

std::optional<MountFromTf> mount_from_tf(const MissionLog& log, const std::string& frame) {
  return mount_from_tf(log.transforms, frame);
}

std::optional<MountFromTf> mount_from_tf(const std::vector<FrameTransform>& transforms,
                                         const std::string& frame) {
  std::map<std::string, const FrameTransform*> parent_of;  // by child: the latest
  for (const auto& t : transforms) parent_of[t.child] = &t;
  const auto camera = in_root(parent_of, frame);
  if (!camera) return std::nullopt;
  for (const char* base : {"base_footprint", "base_link"}) {
    const auto b = in_root(parent_of, base);
    if (!b || b->root != camera->root || frame == base) continue;
    if (b->chain.size() == 1 && camera->root != base) continue;  // the base is not in the tree
    const Eigen::Isometry3d m = b->pose.inverse() * camera->pose;
    MountFromTf out;
    out.xyz = m.translation();
    const Eigen::Matrix3d R = m.linear();
    out.rpy = {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2))),
               std::atan2(R(1, 0), R(0, 0))};
    out.base = base;
    return out;
  }
  return std::nullopt;
}

}  // namespace lampnav::io
