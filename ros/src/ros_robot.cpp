#include "lampnav/ros/ros_robot.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <future>
#include <mutex>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/io/mission_log.hpp"
#include "task_thread.hpp"

namespace lampnav::ros {

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string image_type(const std::string& topic) {
  return ends_with(topic, "/compressed") ? "sensor_msgs/msg/CompressedImage"
                                         : "sensor_msgs/msg/Image";
}

constexpr std::size_t kOdomKept = 400;  // wheel readings (4 s at 100 Hz) for map -> odom

// Starts a camera's decoding thread and, when its image size is known, has it decode frames of
// that size as JPEG and as PNG: the codecs' first use (OpenCV registers them, libjpeg and zlib
// set up) took 10 ms on this machine, and each of the first few frames' pixels went to fresh
// pages. Three frames are held at once, as many as are in flight at a time (one decoded, one
// waiting in the queue, one being processed), so that their memory is there for the images.
std::unique_ptr<detail::TaskThread> decoding_thread(ImageSize size) {
  auto t = std::make_unique<detail::TaskThread>();
  if (size.width <= 0 || size.height <= 0) return t;
  Image8 frame(size.width, size.height);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      frame.pixels[static_cast<std::size_t>(y) * size.width + x] =
          static_cast<std::uint8_t>((x * 7 + y * 13) % 256);
  io::ImageEncoding jpeg;
  jpeg.format = io::ImageEncoding::Format::jpeg;
  jpeg.jpeg_quality = 90;
  io::ImageEncoding png;
  png.format = io::ImageEncoding::Format::png;
  std::vector<std::string> bytes = {io::encode_image(frame, jpeg), io::encode_image(frame, png)};
  t->submit([bytes = std::move(bytes)] {
     std::vector<Image8> held;
     for (int k = 0; k < 3; ++k) held.push_back(io::decode_image(bytes[k % 2], "a warm-up frame"));
   }).get();
  return t;
}

}  // namespace

namespace detail {

enum class InputKind : int { ceiling, omni, odometry, joints, command, pose_estimate };

// An image decoded (CDR, then PNG or JPEG) as soon as it arrives, on its camera's decoding
// thread, so the loop never waits for one image's decoding while it could process another input.
struct DecodedImage {
  Stamp capture;
  Image8 image;
  std::string problem;
};

struct Pending {
  InputKind kind;
  Sample sample;  // its bytes moved to the decoder for images
  std::future<DecodedImage> image;
  // An image's: set when it is dropped, so that its decoding is skipped if not yet begun.
  std::shared_ptr<std::atomic<bool>> dropped;
  // An image counted among its camera's waiting ones (not one held before the node started).
  bool counted = false;

  bool is_image() const { return kind == InputKind::ceiling || kind == InputKind::omni; }
};

struct Inbox {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Pending> queue;
  NodeCounts counts;
  bool closed = false;  // the robot is gone: what comes is dropped
  std::unique_ptr<TaskThread> ceiling_decoder, omni_decoder;
  // Each camera's images in the queue (not yet taken by next()).
  std::size_t ceiling_waiting = 0, omni_waiting = 0;
  bool holding = false;                   // images kept, uncounted, until release_images()
  std::string ceiling_frame, omni_frame;  // the first image's header.frame_id
  std::vector<io::FrameTransform> static_transforms;
  std::vector<std::string> problems;  // from /tf_static and camera_info, not yet reported
  std::optional<io::CameraInfo> ceiling_info, omni_info;

  std::size_t& waiting(InputKind kind) {
    return kind == InputKind::ceiling ? ceiling_waiting : omni_waiting;
  }
  // Drops the oldest image in the queue (the oldest counted one of `kind`, or the oldest of
  // either camera): counted, and not decoded if its decoding has not begun. The caller holds
  // the mutex.
  void drop_oldest_image(std::optional<InputKind> kind) {
    for (auto it = queue.begin(); it != queue.end(); ++it)
      if (it->is_image() && (!kind || (it->kind == *kind && it->counted))) {
        *it->dropped = true;
        ++counts_of(it->kind).dropped;
        if (it->counted) --waiting(it->kind);
        queue.erase(it);
        return;
      }
  }

  InputCounts& counts_of(InputKind kind) {
    switch (kind) {
      case InputKind::ceiling:
        return counts.ceiling;
      case InputKind::omni:
        return counts.omni;
      case InputKind::command:
        return counts.commands;
      case InputKind::pose_estimate:
        return counts.pose_estimates;
      default:
        return counts.odometry;
    }
  }
};

namespace {

// On a camera's decoding thread: touches nothing of the robot's.
DecodedImage decode_image(const std::string& topic, const std::string& cdr) {
  DecodedImage d;
  try {
    if (image_type(topic) == "sensor_msgs/msg/Image") {
      io::ros2::GreyImage g = io::ros2::raw_image_grey(cdr);
      d.capture = g.stamp;
      d.image = std::move(g.image);
    } else {
      const io::ImageFrame f = io::ros2::compressed_image(cdr);
      d.capture = f.stamp;
      d.image = io::decode_image(f.data, topic);
    }
  } catch (const io::CdrError& e) {
    d.problem = e.what();
  } catch (const InputError& e) {
    d.problem = e.message();
  }
  return d;
}

}  // namespace
}  // namespace detail

using detail::InputKind;

void RosRobotOptions::validate() const {
  auto bad = [](const char* field, const std::string& why) {
    throw InputError({"", "node options", field}, why);
  };
  if (!(semi_axis > 0)) bad("semi_axis", "must be positive (robot.json)");
  if (!topics.joint_states.empty() && !(topics.wheel_radius > 0))
    bad("wheel-radius", "wheel joint states need the wheel radius (--wheel-radius, m)");
  if (topics.joint_states.empty() && topics.odometry.empty())
    bad("odometry-topic", "no wheel odometry topic: name --odometry-topic or --joint-states-topic");
  if (topics.ceiling_image.empty() && topics.omni_image.empty())
    bad("ceiling-topic", "neither camera has a topic");
  if (max_queue < 10) bad("max_queue", "must be at least 10");
  if (max_images_waiting < 1) bad("max_images_waiting", "must be at least 1");
  if (!(idle_exit_s >= 0)) bad("idle-exit", "must not be negative");
  if (frames.map.empty() || frames.odom.empty() || frames.base.empty())
    bad("frames", "frame ids must not be empty");
  for (const ImageSize& s : {ceiling_size, omni_size})
    if (s.width < 0 || s.height < 0 || s.width > 8192 || s.height > 8192 ||
        (s.width == 0) != (s.height == 0))
      bad("image size", "a camera's width and height must both be 1 to 8192 px, or both 0");
}

RosRobot::RosRobot(Participant& p, const RosRobotOptions& options)
    : o_(options), odometry_wheels_(options.semi_axis), joint_wheels_(options.topics.wheel_radius) {
  o_.validate();
  const NodeTopics& t = o_.topics;
  cmd_vel_ = &p.writer(t.cmd_vel, "geometry_msgs/msg/Twist", Qos::state);
  pose_ = &p.writer(t.ns + "/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", Qos::state);
  tf_ = &p.writer("/tf", "tf2_msgs/msg/TFMessage", Qos::tf);
  mode_ = &p.writer(t.ns + "/mode", "std_msgs/msg/String", Qos::state);
  hypotheses_ = &p.writer(t.ns + "/hypotheses", "geometry_msgs/msg/PoseArray", Qos::state);
  events_ = &p.writer(t.ns + "/events", "std_msgs/msg/String", Qos::state);
  if (!t.diagnostics.empty())
    diagnostics_ = &p.writer(t.diagnostics, "diagnostic_msgs/msg/DiagnosticArray", Qos::state);
  inbox_ = std::make_shared<detail::Inbox>();
  inbox_->holding = o_.hold_images;
  if (!t.ceiling_image.empty()) inbox_->ceiling_decoder = decoding_thread(o_.ceiling_size);
  if (!t.omni_image.empty()) inbox_->omni_decoder = decoding_thread(o_.omni_size);
  try {
    if (!t.ceiling_image.empty())
      subscribe(p, t.ceiling_image, image_type(t.ceiling_image), Qos::sensor_data,
                InputKind::ceiling);
    if (!t.omni_image.empty())
      subscribe(p, t.omni_image, image_type(t.omni_image), Qos::sensor_data, InputKind::omni);
    if (!t.joint_states.empty())
      subscribe(p, t.joint_states, "sensor_msgs/msg/JointState", Qos::sensor_data,
                InputKind::joints);
    else
      subscribe(p, t.odometry, "nav_msgs/msg/Odometry", Qos::sensor_data, InputKind::odometry);
    subscribe(p, t.command, "std_msgs/msg/String", Qos::state, InputKind::command);
    if (!t.pose_estimate.empty())
      subscribe(p, t.pose_estimate, "geometry_msgs/msg/PoseWithCovarianceStamped", Qos::state,
                InputKind::pose_estimate);
    if (!t.tf_static.empty()) subscribe_static_transforms(p);
    if (!t.ceiling_image.empty()) subscribe_camera_info(p, t.ceiling_image, CameraRole::ceiling);
    if (!t.omni_image.empty()) subscribe_camera_info(p, t.omni_image, CameraRole::omni);
  } catch (...) {
    close();  // the subscriptions made so far stay with the participant
    throw;
  }
}

RosRobot::~RosRobot() {
  stop();
  close();
}

void RosRobot::close() {
  std::unique_ptr<detail::TaskThread> ceiling, omni;
  {
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    inbox_->closed = true;
    for (detail::Pending& p : inbox_->queue)
      if (p.dropped) *p.dropped = true;
    inbox_->queue.clear();
    ceiling = std::move(inbox_->ceiling_decoder);
    omni = std::move(inbox_->omni_decoder);
  }
  // Joined here, outside the lock: the images queued to them whose decoding began are decoded
  // and dropped, the others skipped.
}

void RosRobot::subscribe(Participant& p, const std::string& topic, const std::string& type, Qos qos,
                         InputKind kind) {
  // The callback holds the inbox, never the robot.
  p.subscribe(topic, type, qos,
              [inbox = inbox_, kind, topic, max_queue = o_.max_queue,
               max_images = o_.max_images_waiting](Sample&& s) {
                {
                  std::lock_guard<std::mutex> lock(inbox->mutex);
                  if (inbox->closed) return;
                  detail::Pending pending{kind, std::move(s), {}, {}};
                  const bool image = pending.is_image();
                  if (image) {
                    // The camera's frame, from the first image whose header reads (a header
                    // that does not is refused with the image, by its decoder).
                    std::string& frame =
                        kind == InputKind::ceiling ? inbox->ceiling_frame : inbox->omni_frame;
                    if (frame.empty()) try {
                        frame = io::ros2::message_header(pending.sample.cdr).frame_id;
                      } catch (const io::CdrError&) {
                      }
                    auto dropped = std::make_shared<std::atomic<bool>>(false);
                    pending.dropped = dropped;
                    pending.image =
                        (kind == InputKind::ceiling ? inbox->ceiling_decoder : inbox->omni_decoder)
                            ->submit([topic, cdr = std::move(pending.sample.cdr), dropped] {
                              // Dropped while it waited for the decoder: not decoded.
                              if (*dropped) return detail::DecodedImage{};
                              return detail::decode_image(topic, cdr);
                            });
                  }
                  ++inbox->counts_of(kind).received;
                  // A camera whose images come faster than they are processed has its oldest
                  // waiting image dropped, so that what is processed stays recent and the
                  // queue's memory bounded (ROS 2's sensor-data QoS keeps the last five too).
                  // Images held before the node started are not counted: they go first.
                  pending.counted = image && !inbox->holding;
                  const bool counted = pending.counted;
                  inbox->queue.push_back(std::move(pending));
                  if (counted && ++inbox->waiting(kind) > max_images)
                    inbox->drop_oldest_image(kind);
                  // Behind by more than the queue holds: an old image goes first (odometry and
                  // commands are small and each one counts).
                  if (inbox->queue.size() > max_queue) inbox->drop_oldest_image(std::nullopt);
                }
                inbox->ready.notify_one();
              });
}

namespace {

// Subscribes a small message decoded as it comes, on the DDS thread: counted in the inbox's
// `counts`; one that does not decode refused and kept to be reported (at most 100 until they
// are); `take` keeps what decoded, the inbox's mutex held.
template <class Value, class Take>
void subscribe_decoded(Participant& p, const std::string& topic, const std::string& type, Qos qos,
                       std::shared_ptr<detail::Inbox> inbox, InputCounts NodeCounts::*counts,
                       Value (*decode)(const std::string&), Take take) {
  p.subscribe(topic, type, qos, [inbox, topic, counts, decode, take](Sample&& s) {
    std::optional<Value> value;
    std::string problem;
    try {
      value = decode(s.cdr);
    } catch (const io::CdrError& e) {
      problem = e.what();
    }
    std::lock_guard<std::mutex> lock(inbox->mutex);
    if (inbox->closed) return;
    InputCounts& c = inbox->counts.*counts;
    ++c.received;
    if (!value) {
      ++c.refused;
      if (inbox->problems.size() < 100)
        inbox->problems.push_back(topic + ", message " + std::to_string(s.sequence) + ": " +
                                  problem);
      return;
    }
    ++c.used;
    take(*inbox, std::move(*value));
  });
}

}  // namespace

void RosRobot::subscribe_static_transforms(Participant& p) {
  // A few small messages, at start. The latest of each child frame is kept (as mount_from_tf
  // takes them), in place: a publisher that sends its transforms again and again takes no more
  // memory.
  subscribe_decoded(p, o_.topics.tf_static, "tf2_msgs/msg/TFMessage", Qos::tf_static, inbox_,
                    &NodeCounts::static_transforms, &io::ros2::tf_transforms,
                    [](detail::Inbox& inbox, std::vector<io::FrameTransform> transforms) {
                      auto& kept = inbox.static_transforms;
                      for (auto& t : transforms) {
                        t.is_static = true;
                        const auto same =
                            std::find_if(kept.begin(), kept.end(),
                                         [&](const auto& k) { return k.child == t.child; });
                        if (same != kept.end())
                          *same = std::move(t);
                        else
                          kept.push_back(std::move(t));
                      }
                    });
}

std::string camera_info_topic(const std::string& image_topic) {
  std::string base = image_topic;
  if (ends_with(base, "/compressed")) base.erase(base.size() - 11);
  const auto slash = base.rfind('/');
  return (slash == std::string::npos || slash == 0 ? std::string() : base.substr(0, slash)) +
         "/camera_info";
}

void RosRobot::subscribe_camera_info(Participant& p, const std::string& image_topic,
                                     CameraRole camera) {
  // As often as the images; the newest kept.
  subscribe_decoded(p, camera_info_topic(image_topic), "sensor_msgs/msg/CameraInfo",
                    Qos::sensor_data, inbox_, &NodeCounts::camera_info, &io::ros2::camera_info,
                    [camera](detail::Inbox& inbox, io::CameraInfo info) {
                      (camera == CameraRole::ceiling ? inbox.ceiling_info : inbox.omni_info) =
                          std::move(info);
                    });
}

std::optional<io::CameraInfo> RosRobot::camera_info(CameraRole camera) const {
  std::lock_guard<std::mutex> lock(inbox_->mutex);
  return camera == CameraRole::ceiling ? inbox_->ceiling_info : inbox_->omni_info;
}

void RosRobot::release_images() {
  std::lock_guard<std::mutex> lock(inbox_->mutex);
  inbox_->holding = false;
}

std::string RosRobot::camera_frame(CameraRole camera) const {
  std::lock_guard<std::mutex> lock(inbox_->mutex);
  return camera == CameraRole::ceiling ? inbox_->ceiling_frame : inbox_->omni_frame;
}

std::vector<io::FrameTransform> RosRobot::static_transforms() {
  std::vector<std::string> problems;
  std::vector<io::FrameTransform> out;
  {
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    problems.swap(inbox_->problems);
    out = inbox_->static_transforms;
  }
  if (on_problem)
    for (const auto& p : problems) on_problem(p);
  return out;
}

const std::string& RosRobot::topic_of(InputKind kind) const {
  const NodeTopics& t = o_.topics;
  switch (kind) {
    case InputKind::ceiling:
      return t.ceiling_image;
    case InputKind::omni:
      return t.omni_image;
    case InputKind::odometry:
      return t.odometry;
    case InputKind::joints:
      return t.joint_states;
    case InputKind::pose_estimate:
      return t.pose_estimate;
    default:
      return t.command;
  }
}

NodeCounts RosRobot::counts() const {
  std::lock_guard<std::mutex> lock(inbox_->mutex);
  return inbox_->counts;
}

void RosRobot::stop() {
  stop_ = true;
  inbox_->ready.notify_all();
}

void RosRobot::set_wheel_speeds(double left, double right) {
  cmd_vel_->write(io::ros2::twist((left + right) / 2, (right - left) / (2 * o_.semi_axis)));
}

std::optional<RobotInput> RosRobot::next() {
  for (;;) {
    detail::Pending p;
    {
      std::unique_lock<std::mutex> lock(inbox_->mutex);
      for (;;) {
        if (stop_) return std::nullopt;
        if (!inbox_->queue.empty()) break;
        if (o_.idle_exit_s > 0 && any_input_ &&
            Clock::now() - last_input_ > std::chrono::duration<double>(o_.idle_exit_s))
          return std::nullopt;
        inbox_->ready.wait_for(lock, std::chrono::milliseconds(20));
      }
      p = std::move(inbox_->queue.front());
      inbox_->queue.pop_front();
      if (p.counted) --inbox_->waiting(p.kind);
    }
    any_input_ = true;
    last_input_ = Clock::now();
    last_arrival_ = p.sample.arrival;
    std::optional<RobotInput> in;
    std::string problem;
    try {
      in = decode(p);
    } catch (const io::CdrError& e) {
      problem = e.what();
    } catch (const InputError& e) {
      problem = e.message();
    }
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    InputCounts& c = inbox_->counts_of(p.kind);
    if (!problem.empty()) {
      ++c.refused;
      if (on_problem)
        on_problem(topic_of(p.kind) + ", message " + std::to_string(p.sample.sequence) + ": " +
                   problem);
      continue;
    }
    if (!in) continue;  // nothing new (an odometry stamp not later than the last)
    ++c.used;
    last_ready_ = Clock::now();
    return in;
  }
}

std::optional<RobotInput> RosRobot::decode(detail::Pending& p) {
  const std::string& cdr = p.sample.cdr;
  switch (p.kind) {
    case InputKind::ceiling:
    case InputKind::omni: {
      detail::DecodedImage d = p.image.get();
      if (!d.problem.empty()) throw io::CdrError(d.problem);
      FrameInput in;
      in.camera = p.kind == InputKind::ceiling ? CameraRole::ceiling : CameraRole::omni;
      in.capture = d.capture;
      // Robot time: the newest wheel reading, or the capture when it is later.
      in.arrival =
          last_wheel_stamp_ && *last_wheel_stamp_ > d.capture ? *last_wheel_stamp_ : d.capture;
      in.image = std::move(d.image);
      return in;
    }
    case InputKind::odometry: {
      const io::OdometryPose o = io::ros2::odometry(cdr);
      const auto w = odometry_wheels_.add(o);
      if (!w) return std::nullopt;
      odom_.emplace_back(o.stamp, o.pose);
      last_wheel_stamp_ = w->stamp;
      if (odom_.size() > kOdomKept) odom_.pop_front();
      return WheelInput{w->stamp, w->left, w->right};
    }
    case InputKind::joints: {
      const io::WheelJoints j =
          io::ros2::wheel_joints(cdr, o_.topics.left_joint, o_.topics.right_joint);
      const auto w = joint_wheels_.add(j);
      if (!w) return std::nullopt;
      // The odometry frame: the wheels integrated by the conventions' motion model.
      Pose2 pose = odom_.empty() ? Pose2() : odom_.back().second;
      if (last_wheels_) {
        const fusion::StateVector x =
            fusion::predict_motion(pose.vector(), w->left - last_wheels_->left,
                                   w->right - last_wheels_->right, o_.semi_axis);
        pose = Pose2(x.x(), x.y(), wrap_angle(x.z()));
      }
      last_wheels_ = WheelInput{w->stamp, w->left, w->right};
      odom_.emplace_back(w->stamp, pose);
      if (odom_.size() > kOdomKept) odom_.pop_front();
      last_wheel_stamp_ = w->stamp;
      return *last_wheels_;
    }
    case InputKind::command:
      return CommandInput{last_wheel_stamp_.value_or(Stamp{}), io::ros2::string_data(cdr)};
    case InputKind::pose_estimate: {
      const io::ros2::PoseEstimate e = io::ros2::pose_estimate(cdr);
      if (e.frame_id != o_.frames.map)
        throw io::CdrError("header.frame_id is '" + e.frame_id +
                           "': a pose estimate must be in the '" + o_.frames.map + "' frame");
      // Where the robot is now: at the newest wheel reading (the estimate's own stamp is the
      // clock of whatever published it, RViz's or Foxglove's, not necessarily the robot's).
      return PoseInput{last_wheel_stamp_.value_or(e.stamp), e.pose, e.covariance};
    }
  }
  return std::nullopt;
}

void RosRobot::publish(const fusion::LocalizerEstimate& e) {
  const NodeFrames& f = o_.frames;
  if (e.known()) {
    pose_->write(io::ros2::pose_with_covariance_stamped(e.stamp, f.map, e.pose, e.covariance));
    // map -> odom from the odometry pose at the estimate's wheel reading (or the one before).
    const std::pair<Stamp, Pose2>* at = nullptr;
    for (auto it = odom_.rbegin(); it != odom_.rend(); ++it)
      if (it->first <= e.stamp) {
        at = &*it;
        break;
      }
    if (at)
      tf_->write(io::ros2::tf_message({{e.stamp, f.map, f.odom, e.pose * at->second.inverse()}}));
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    ++inbox_->counts.poses_published;
  }
  if (!last_mode_ || *last_mode_ != e.mode) {
    mode_->write(io::ros2::string_message(fusion::to_string(e.mode)));
    last_mode_ = e.mode;
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    inbox_->counts.mode = fusion::to_string(e.mode);
  }
  const double leader = e.hypotheses.empty() ? -1 : e.hypotheses.front().weight;
  if (e.hypotheses.size() != last_hypotheses_ || leader != last_leader_weight_) {
    std::vector<Pose2> poses;
    for (const auto& h : e.hypotheses) poses.push_back(h.pose);
    hypotheses_->write(io::ros2::pose_array(e.stamp, f.map, poses));
    last_hypotheses_ = e.hypotheses.size();
    last_leader_weight_ = leader;
    std::lock_guard<std::mutex> lock(inbox_->mutex);
    inbox_->counts.hypotheses = e.hypotheses.size();
  }
}

void RosRobot::publish_diagnostics(const std::vector<io::ros2::DiagnosticStatus>& statuses) {
  if (!diagnostics_) return;
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  diagnostics_->write(io::ros2::diagnostic_array(
      stamp_from_nanoseconds(std::chrono::duration_cast<std::chrono::nanoseconds>(now).count()),
      statuses));
}

void RosRobot::publish_event(const std::string& text) {
  events_->write(io::ros2::string_message(text));
}

}  // namespace lampnav::ros
