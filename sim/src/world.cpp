#include "world.hpp"

#include <cmath>
#include <cstdio>

#include "lampnav/core/error.hpp"

namespace lampnav::sim {

using Eigen::Vector2d;

namespace {

// A kidnap without a destination: a random pose along a corridor's axis, or in a hall.
Pose2 random_place(const graph::TopologicalMap& map, std::mt19937_64& rng) {
  std::vector<const graph::Node*> candidates;
  for (const auto& n : map.nodes()) {
    if ((n.place == graph::Place::corridor && n.axis) || n.place == graph::Place::hall)
      candidates.push_back(&n);
  }
  if (candidates.empty())
    throw InputError({"", "scenario", "kidnaps"},
                     "the map has no corridor or hall to put the robot down in");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const graph::Node& n =
      *candidates[static_cast<std::size_t>(u(rng) * candidates.size()) % candidates.size()];
  if (n.axis) {
    const Vector2d p = n.axis->point_at((0.15 + 0.7 * u(rng)) * n.axis->length());
    const double yaw =
        std::atan2(n.axis->direction().y(), n.axis->direction().x()) + (u(rng) < 0.5 ? 0 : M_PI);
    return {p, yaw};
  }
  const Vector2d c = n.region.centroid();
  return {c, 2 * M_PI * u(rng)};
}

}  // namespace

World::World(const Scenario& s, const std::string& log_path)
    // Independent random streams, all from the one seed, so that (say) a frame drop does not
    // change the odometry noise that follows.
    : s_(s),
      rng_events_(s.seed * 0x9E3779B97F4A7C15ULL + 1),
      rng_render_(s.seed * 0x9E3779B97F4A7C15ULL + 2),
      rng_bumps_(s.seed * 0x9E3779B97F4A7C15ULL + 3),
      encoders_(s.odometry, s.seed * 0x9E3779B97F4A7C15ULL + 4),
      true_axis_(s.robot.semi_axis * (1.0 + s.odometry.semi_axis_error)),
      log_(log_path),
      dt_ns_(std::llround(1e9 / s.odometry_rate)),
      ceiling_ns_(s.ceiling_rate > 0 ? std::llround(1e9 / s.ceiling_rate) : 0),
      omni_ns_(s.omni_rate > 0 ? std::llround(1e9 / s.omni_rate) : 0),
      pose_(s.start) {
  if (s.ceiling_rate > 0) ceiling_.emplace(*s.robot.find_camera("ceiling_camera"), s.ceiling);
  if (s.omni_rate > 0) omni_.emplace(*s.robot.find_camera("omni_camera"), s.omni);
  log_.attach_robot(to_robot_json(s.robot));
  log_.attach_map(s.map_geojson);
  const Stamp t0 = stamp_from_nanoseconds(0);
  for (const auto& text : s.commands) log_.write(t0, io::CommandMessage{t0, text});
  for (const auto& id : s.failed_lamps)
    log_.write(t0, io::MissionEvent{t0, io::EventKind::lamp_failure, id});
  for (const auto& n : s.map.nodes())
    for (const auto& l : n.lamps)
      if (!s.failed_lamps.count(l.id.value)) working_.push_back(&l);
}

std::vector<const graph::Lamp*> World::lamps_near(const Pose2& p, double radius) const {
  std::vector<const graph::Lamp*> out;
  for (const graph::Lamp* l : s_.map.lamps_within(p.translation(), radius))
    if (!s_.failed_lamps.count(l->id.value)) out.push_back(l);
  return out;
}

CameraTilt World::tilt() {
  CameraTilt t;
  if (s_.bump_sigma_rad > 0) {
    std::normal_distribution<double> bump(0.0, 1.0);
    t.roll = s_.bump_sigma_rad * bump(rng_bumps_);
    t.pitch = s_.bump_sigma_rad * bump(rng_bumps_);
  }
  return t;
}

void World::write_state() {
  const Stamp t = stamp_from_nanoseconds(t_ns_);
  const WheelTravel& r = encoders_.readings();
  log_.write(t, io::WheelReading{t, r.left, r.right});
  log_.write(t, io::TruthPose{t, pose_});
  ++stats_.wheel_messages;
}

void World::capture(bool is_ceiling) {
  const Stamp t = stamp_from_nanoseconds(t_ns_);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  if (uni(rng_events_) < s_.frame_drop_probability) {
    ++stats_.dropped_frames;
    log_.write(t, io::MissionEvent{t, io::EventKind::frame_drop,
                                   is_ceiling ? "ceiling_camera" : "omni_camera"});
    return;
  }
  const CameraTilt tl = tilt();
  Image8 img = is_ceiling ? ceiling_->render(pose_, tl, lamps_near(pose_, 6.0), rng_render_)
                          : omni_->render(pose_, tl, working_, rng_render_);
  io::ImageFrame f{t, is_ceiling ? "ceiling_camera" : "omni_camera", s_.images.format_name(),
                   io::encode_image(img, s_.images)};
  if (s_.images.format == io::ImageEncoding::Format::jpeg)
    img = io::decode_image(f.data, "simulated frame");
  const double delay = is_ceiling ? s_.ceiling_delay_s : s_.omni_delay_s;
  pending_.push({t_ns_ + static_cast<std::int64_t>(std::llround(delay * 1e9)), order_++,
                 std::move(f), std::move(img)});
  ++(is_ceiling ? stats_.ceiling_frames : stats_.omni_frames);
}

void World::drive(double forward, double turn) {
  const WheelTravel travel =
      wheel_travel(forward * dt_ns_ * 1e-9, turn * dt_ns_ * 1e-9, true_axis_);
  pose_ = sim::drive(pose_, travel, true_axis_);
  stats_.path_length_m += std::fabs(0.5 * (travel.left + travel.right));
  encoders_.step(travel);
  t_ns_ += dt_ns_;
  stats_.duration_s = t_ns_ * 1e-9;
  write_state();
  if (ceiling_ && t_ns_ >= next_ceiling_) {
    capture(true);
    next_ceiling_ += ceiling_ns_;
  }
  if (omni_ && t_ns_ >= next_omni_) {
    capture(false);
    next_omni_ += omni_ns_;
  }
}

void World::hold() { write_state(); }

void World::advance() {
  t_ns_ += dt_ns_;
  stats_.duration_s = t_ns_ * 1e-9;
}

void World::place(const Pose2& pose) { pose_ = pose; }

void World::put_down(const Pose2& pose, const std::string& detail) {
  pose_ = pose;
  const Stamp t = stamp_from_nanoseconds(t_ns_);
  char where[96];
  std::snprintf(where, sizeof where, "put down at (%.2f, %.2f, %.1f deg)", pose.x(), pose.y(),
                pose.yaw() * 180 / M_PI);
  log_.write(t, io::MissionEvent{t, io::EventKind::kidnap, detail.empty() ? where : detail});
  ++stats_.kidnaps;
}

void World::capture_all() {
  if (omni_) capture(false);
  if (ceiling_) capture(true);
}

std::vector<ArrivedFrame> World::deliver(std::int64_t until_ns) {
  std::vector<ArrivedFrame> out;
  while (!pending_.empty() && pending_.top().available_ns <= until_ns) {
    // priority_queue::top is const: the image is copied out (one frame at a time).
    const Pending& p = pending_.top();
    log_.write_image(stamp_from_nanoseconds(p.available_ns), p.frame);
    out.push_back({p.frame.frame_id == "ceiling_camera", to_nanoseconds(p.frame.stamp),
                   p.available_ns, p.image});
    pending_.pop();
  }
  return out;
}

void World::finish() {
  if (finished_) return;
  finished_ = true;
  deliver(INT64_MAX);
  log_.close();
  stats_.slips = encoders_.slips();
}

Pose2 World::random_place() { return sim::random_place(s_.map, rng_events_); }

}  // namespace lampnav::sim
