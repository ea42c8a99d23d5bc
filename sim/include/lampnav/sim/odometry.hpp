#pragma once
// The simulated robot's wheels: true motion of a differential drive, and encoders that report it
// with the errors real ones have (paper 2's odometry drifts; the EKF exists because of it).

#include <random>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::sim {

struct OdometryErrors {
  double left_scale = 0.004;        // fraction: systematic wheel-radius error, left encoder
  double right_scale = -0.003;      // fraction: systematic wheel-radius error, right encoder
  double semi_axis_error = 0.01;    // fraction: the true semi-axis differs from robot.json's
  double noise_per_sqrt_m = 0.002;  // m per sqrt(m): random error per wheel, grows with travel
  double slip_per_m = 0.02;         // slips per metre of wheel travel
  double slip_fraction = 0.3;       // a slip over-reports that step's increment by this fraction
  // Throws lampnav::InputError naming the field when a value is out of range.
  void validate() const;
  static OdometryErrors none();
};

// True wheel motion of a differential drive with semi-axis `a`: wheel travels for a body motion.
struct WheelTravel {
  double left = 0, right = 0;  // m
};
WheelTravel wheel_travel(double forward, double turn, double semi_axis);
// The true pose after the wheels travel (mid-point unicycle, conventions.md).
Pose2 drive(const Pose2& pose, const WheelTravel& travel, double semi_axis);

// Encoders: cumulative measured travel per wheel.
class WheelEncoders {
 public:
  WheelEncoders(const OdometryErrors& errors, std::uint64_t seed);
  // Adds one step of true wheel travel; returns the cumulative readings.
  WheelTravel step(const WheelTravel& truth);
  const WheelTravel& readings() const { return cumulative_; }
  int slips() const { return slips_; }

 private:
  double measure(double truth, double scale);
  OdometryErrors e_;
  std::mt19937_64 rng_;
  WheelTravel cumulative_;
  int slips_ = 0;
};

}  // namespace lampnav::sim
