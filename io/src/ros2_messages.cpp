#include "lampnav/io/ros2_messages.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

#include "cdr.hpp"
#include "raw_pixels.hpp"

namespace lampnav::io::ros2 {

namespace {

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
}  // namespace

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

GreyImage raw_image_grey(const std::string& data) {
  CdrReader r(data);
  const Header h = header(r);
  GreyImage f;
  f.stamp = h.stamp;
  f.frame_id = h.frame_id;
  detail::RawPixels raw;
  raw.height = r.u32("height");
  raw.width = r.u32("width");
  raw.encoding = r.string("encoding");
  raw.big_endian = r.u8("is_bigendian") != 0;
  raw.step = r.u32("step");
  const std::string pixels = r.bytes("data");
  raw.data = &pixels;
  f.image = detail::grey_from_raw(raw);
  return f;
}

ImageFrame raw_image(const std::string& data) {
  GreyImage g = raw_image_grey(data);
  ImageFrame f;
  f.stamp = g.stamp;
  f.frame_id = std::move(g.frame_id);
  f.format = "png";
  f.data = encode_png(g.image, 1);
  return f;
}

namespace {

// geometry_msgs/msg/Pose (in `pose.pose`) as a planar pose: finite, its orientation a unit
// quaternion (1 %), yaw taken from it.
Pose2 planar_pose(CdrReader& r) {
  const double x = r.f64("pose.pose.position.x"), y = r.f64("pose.pose.position.y");
  r.f64("pose.pose.position.z");
  const double qx = r.f64("pose.pose.orientation.x"), qy = r.f64("pose.pose.orientation.y"),
               qz = r.f64("pose.pose.orientation.z"), qw = r.f64("pose.pose.orientation.w");
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(qx) || !std::isfinite(qy) ||
      !std::isfinite(qz) || !std::isfinite(qw))
    throw CdrError("pose.pose is not finite");
  if (std::abs(std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw) - 1) > 0.01)
    throw CdrError("pose.pose.orientation is not a unit quaternion");
  return Pose2(x, y, std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz)));
}

}  // namespace

OdometryPose odometry(const std::string& data) {
  CdrReader r(data);
  OdometryPose o;
  o.stamp = header(r).stamp;
  r.string("child_frame_id");
  o.pose = planar_pose(r);
  for (int k = 0; k < 36; ++k) r.f64("pose.covariance");
  for (int k = 0; k < 6 + 36; ++k) r.f64("twist");
  return o;
}

PoseEstimate pose_estimate(const std::string& data) {
  CdrReader r(data);
  PoseEstimate e;
  const Header h = header(r);
  e.stamp = h.stamp;
  e.frame_id = h.frame_id;
  e.pose = planar_pose(r);
  double c[36];
  for (double& v : c) v = r.f64("pose.covariance");
  // Row-major 6 x 6 over (x, y, z, roll, pitch, yaw): the planar part.
  constexpr int kAt[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e.covariance(i, j) = c[6 * kAt[i] + kAt[j]];
  const Eigen::Matrix3d& P = e.covariance;
  if (!P.allFinite() || !P.isApprox(P.transpose(), 1e-9) ||
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P, Eigen::EigenvaluesOnly).eigenvalues()(0) <=
          0)
    throw CdrError(
        "pose.covariance: the x, y and yaw block must be symmetric positive definite (RViz sends "
        "variances of 0.25 m^2, 0.25 m^2 and 0.0685 rad^2)");
  return e;
}

// sensor_msgs/msg/JointState: the positions of the two wheel joints, found by name.
WheelJoints wheel_joints(const std::string& data, const std::string& left_name,
                         const std::string& right_name) {
  CdrReader r(data);
  WheelJoints w;
  w.stamp = header(r).stamp;
  const std::vector<std::string> names = r.strings("name");
  const std::vector<double> position = r.f64s("position");
  r.f64s("velocity");  // read to check the message is whole
  r.f64s("effort");
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

std::vector<FrameTransform> tf_transforms(const std::string& data) {
  CdrReader r(data);
  // Each element at least: header (8 + 4), child (4), 7 doubles.
  const std::uint32_t n = r.count("transforms", 12 + 4 + 7 * 8);
  std::vector<FrameTransform> out(n);
  for (auto& t : out) {
    const Header h = header(r);
    t.stamp = h.stamp;
    t.parent = h.frame_id;
    t.child = r.string("child_frame_id");
    for (int k = 0; k < 3; ++k) t.translation[k] = r.f64("transform.translation");
    double q[4];
    for (auto& v : q) v = r.f64("transform.rotation");
    t.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
    if (!t.translation.allFinite() || !t.rotation.coeffs().allFinite())
      throw CdrError("transform " + t.parent + " -> " + t.child + " is not finite");
    if (std::abs(t.rotation.norm() - 1) > 1e-3)
      throw CdrError("transform " + t.parent + " -> " + t.child +
                     ": the rotation is not a unit quaternion");
    if (t.parent.empty() || t.child.empty() || t.parent == t.child)
      throw CdrError("a transform needs two different frame ids");
    t.rotation.normalize();
  }
  return out;
}

MessageHeader message_header(const std::string& data) {
  CdrReader r(data);
  const Header h = header(r);
  return {h.stamp, h.frame_id};
}

std::string string_data(const std::string& data) {
  CdrReader r(data);
  return r.string("data");
}

// --- Encoders ---

namespace {

std::int64_t ns(Stamp t) { return to_nanoseconds(t); }

void pose(CdrWriter& w, const Pose2& p) {
  w.f64(p.x()).f64(p.y()).f64(0);
  w.f64(0).f64(0).f64(std::sin(p.yaw() / 2)).f64(std::cos(p.yaw() / 2));
}

}  // namespace

std::string pose_with_covariance_stamped(Stamp stamp, const std::string& frame, const Pose2& p,
                                         const Eigen::Matrix3d& c, double fixed_variance) {
  CdrWriter w;
  w.header(ns(stamp), frame);
  pose(w, p);
  // Row-major 6 x 6 over (x, y, z, roll, pitch, yaw).
  constexpr int kAt[6] = {0, 1, -1, -1, -1, 2};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      w.f64(kAt[i] >= 0 && kAt[j] >= 0 ? c(kAt[i], kAt[j]) : i == j ? fixed_variance : 0.0);
  return w.take();
}

std::string pose_array(Stamp stamp, const std::string& frame, const std::vector<Pose2>& poses) {
  CdrWriter w;
  w.header(ns(stamp), frame);
  w.u32(static_cast<std::uint32_t>(poses.size()));
  for (const auto& p : poses) pose(w, p);
  return w.take();
}

std::string tf_message(const std::vector<Transform>& transforms) {
  std::vector<FrameTransform> spatial;
  spatial.reserve(transforms.size());
  for (const auto& t : transforms) {
    FrameTransform f;
    f.stamp = t.stamp;
    f.parent = t.parent;
    f.child = t.child;
    f.translation = {t.pose.x(), t.pose.y(), 0};
    // About z: written as pose() writes an orientation, (0, 0, sin, cos) of half the yaw.
    f.rotation = Eigen::Quaterniond(std::cos(t.pose.yaw() / 2), 0, 0, std::sin(t.pose.yaw() / 2));
    spatial.push_back(std::move(f));
  }
  return tf_message(spatial);
}

std::string tf_message(const std::vector<FrameTransform>& transforms) {
  CdrWriter w;
  w.u32(static_cast<std::uint32_t>(transforms.size()));
  for (const auto& t : transforms) {
    w.header(ns(t.stamp), t.parent).string(t.child);
    w.f64(t.translation.x()).f64(t.translation.y()).f64(t.translation.z());
    const Eigen::Quaterniond& q = t.rotation;
    w.f64(q.x()).f64(q.y()).f64(q.z()).f64(q.w());
  }
  return w.take();
}

std::string twist(double forward, double turn) {
  return CdrWriter().f64(forward).f64(0).f64(0).f64(0).f64(0).f64(turn).take();
}

std::string string_message(const std::string& text) { return CdrWriter().string(text).take(); }

std::string diagnostic_array(Stamp stamp, const std::vector<DiagnosticStatus>& statuses) {
  CdrWriter w;
  w.header(ns(stamp), "");
  w.u32(static_cast<std::uint32_t>(statuses.size()));
  for (const auto& s : statuses) {
    w.u8(s.level).string(s.name).string(s.message).string(s.hardware_id);
    w.u32(static_cast<std::uint32_t>(s.values.size()));
    for (const auto& [key, value] : s.values) w.string(key).string(value);
  }
  return w.take();
}

std::string compressed_image_message(Stamp stamp, const std::string& frame,
                                     const std::string& format, const std::string& data) {
  return CdrWriter().header(ns(stamp), frame).string(format).bytes(data).take();
}

std::string odometry_message(Stamp stamp, const std::string& frame, const std::string& child,
                             const Pose2& p) {
  CdrWriter w;
  w.header(ns(stamp), frame).string(child);
  pose(w, p);
  for (int k = 0; k < 36; ++k) w.f64(0);
  for (int k = 0; k < 6 + 36; ++k) w.f64(0);
  return w.take();
}

std::string joint_state_message(Stamp stamp, const std::vector<std::string>& names,
                                const std::vector<double>& positions) {
  CdrWriter w;
  w.header(ns(stamp), "").strings(names).f64s(positions).f64s({}).f64s({});
  return w.take();
}

// --- Wheel travel ---

std::optional<WheelReading> OdometryWheels::add(const OdometryPose& o) {
  if (!last_) {
    last_ = o;
    return WheelReading{o.stamp, 0.0, 0.0};
  }
  if (!(o.stamp > last_->stamp)) return std::nullopt;
  const Pose2 step = last_->pose.between(o.pose);
  const double dyaw = step.yaw();
  const double ds = std::copysign(step.translation().norm(), step.x());
  left_ += ds - semi_axis_ * dyaw;
  right_ += ds + semi_axis_ * dyaw;
  last_ = o;
  return WheelReading{o.stamp, left_, right_};
}

std::optional<WheelReading> JointWheels::add(const WheelJoints& j) {
  if (!first_) first_ = j;
  if (last_ && !(j.stamp > *last_)) return std::nullopt;
  last_ = j.stamp;
  return WheelReading{j.stamp, radius_ * (j.left - first_->left),
                      radius_ * (j.right - first_->right)};
}

}  // namespace lampnav::io::ros2
