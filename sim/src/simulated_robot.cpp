#include "lampnav/sim/simulated_robot.hpp"

#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace lampnav::sim {

SimulatedRobot::SimulatedRobot(const Scenario& scenario, const std::string& log_path)
    : scenario_(scenario) {
  scenario_.validate();
  world_ = std::make_unique<World>(scenario_, log_path);
  world_->hold();  // the state at t = 0, and its reading as the first input
  queue_.push_back(WheelInput{stamp_from_nanoseconds(0), 0.0, 0.0});
}

SimulatedRobot::~SimulatedRobot() { finish(); }

void SimulatedRobot::set_wheel_speeds(double left, double right) {
  // The motors cannot go faster than the scenario's top speed; NaN stops them.
  const double top = 1.5 * scenario_.max_speed;
  left_ = std::isfinite(left) ? std::clamp(left, -top, top) : 0.0;
  right_ = std::isfinite(right) ? std::clamp(right, -top, top) : 0.0;
}

std::optional<RobotInput> SimulatedRobot::next() {
  if (queue_.empty()) {
    if (finished_ || world_->now_ns() >= static_cast<std::int64_t>(scenario_.max_duration_s * 1e9))
      return std::nullopt;
    if (next_kidnap_ < scenario_.kidnaps.size() &&
        world_->now_ns() * 1e-9 >= scenario_.kidnaps[next_kidnap_].at_s) {
      const Kidnap& k = scenario_.kidnaps[next_kidnap_++];
      world_->put_down(k.to ? *k.to : world_->random_place());
    }
    // The commanded wheel speeds move the true wheels (the true semi-axis turns the body).
    const double a = world_->true_semi_axis();
    world_->drive(0.5 * (left_ + right_), (right_ - left_) / (2 * a));
    const WheelTravel& r = world_->readings();
    queue_.push_back(
        WheelInput{stamp_from_nanoseconds(world_->now_ns()), r.left, r.right});
    for (ArrivedFrame& f : world_->deliver(world_->now_ns()))
      queue_.push_back(FrameInput{
          f.ceiling ? CameraRole::ceiling : CameraRole::omni,
          stamp_from_nanoseconds(f.capture_ns), stamp_from_nanoseconds(f.arrival_ns),
          std::move(f.image)});
  }
  RobotInput in = std::move(queue_.front());
  queue_.pop_front();
  return in;
}

Pose2 SimulatedRobot::truth() const { return world_->pose(); }
double SimulatedRobot::now_s() const { return world_->now_ns() * 1e-9; }

RecordStats SimulatedRobot::finish() {
  if (!finished_) {
    finished_ = true;
    world_->finish();
  }
  return world_->stats();
}

}  // namespace lampnav::sim
