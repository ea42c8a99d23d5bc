#pragma once
// The simulated world of a scenario as time goes by: the true pose, the encoders, both cameras
// (frames captured on schedule, delivered after their delay, some dropped), floor bumps and
// kidnaps, everything written to the mission log as it happens. record_mission drives it like a
// person at a joystick; SimulatedRobot lets the stack drive it.

#include <cstdint>
#include <optional>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "lampnav/core/image.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"

namespace lampnav::sim {

struct ArrivedFrame {
  bool ceiling = true;
  std::int64_t capture_ns = 0, arrival_ns = 0;
  Image8 image;
};

class World {
 public:
  World(const Scenario& scenario, const std::string& log_path);

  std::int64_t now_ns() const { return t_ns_; }
  std::int64_t period_ns() const { return dt_ns_; }
  const Pose2& pose() const { return pose_; }
  double true_semi_axis() const { return true_axis_; }
  const WheelTravel& readings() const { return encoders_.readings(); }
  const Scenario& scenario() const { return s_; }
  RecordStats& stats() { return stats_; }

  // One odometry period at body speeds (m/s, rad/s): the true motion, the encoders, the state
  // written, and the frames due on the cameras' schedules captured.
  void drive(double forward, double turn);
  // The state written at the present instant, standing still (a carried robot between stops),
  // and the clock moved on by one odometry period.
  void hold();
  void advance();
  // Where the robot starts (no event).
  void place(const Pose2& pose);
  // Lifted and put down (a kidnap event in the log, saying where, or `detail`); odometry knows
  // nothing of it.
  void put_down(const Pose2& pose, const std::string& detail = {});
  // A frame from each camera that the scenario has, now.
  void capture_all();
  // The frames that have arrived by `until_ns`, written to the log and handed out in order.
  std::vector<ArrivedFrame> deliver(std::int64_t until_ns);
  // Delivers everything still in flight and closes the log.
  void finish();

  // Random places for kidnaps without a destination, and other event draws, from the seed.
  Pose2 random_place();
  std::mt19937_64& event_rng() { return rng_events_; }

 private:
  struct Pending {
    std::int64_t available_ns;
    std::uint64_t order;
    io::ImageFrame frame;
    Image8 image;
    bool operator>(const Pending& o) const {
      return available_ns != o.available_ns ? available_ns > o.available_ns : order > o.order;
    }
  };
  void write_state();
  void capture(bool ceiling);
  CameraTilt tilt();
  std::vector<const graph::Lamp*> lamps_near(const Pose2& p, double radius) const;

  const Scenario& s_;
  RecordStats stats_;
  std::mt19937_64 rng_events_, rng_render_, rng_bumps_;
  WheelEncoders encoders_;
  double true_axis_;
  std::optional<CeilingRenderer> ceiling_;
  std::optional<OmniRenderer> omni_;
  io::MissionLogWriter log_;
  std::vector<const graph::Lamp*> working_;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> pending_;
  std::uint64_t order_ = 0;
  std::int64_t dt_ns_, ceiling_ns_, omni_ns_;
  std::int64_t t_ns_ = 0, next_ceiling_ = 0, next_omni_ = 0;
  Pose2 pose_;
  bool finished_ = false;
};

}  // namespace lampnav::sim
