#include "lampnav/sim/odometry.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"

namespace lampnav::sim {

void OdometryErrors::validate() const {
  auto check = [](double v, double lo, double hi, const char* field) {
    if (!(v >= lo && v <= hi)) {
      throw InputError({"", "odometry errors", field},
                       "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    }
  };
  check(left_scale, -0.2, 0.2, "left_scale");
  check(right_scale, -0.2, 0.2, "right_scale");
  check(semi_axis_error, -0.2, 0.2, "semi_axis_error");
  check(noise_per_sqrt_m, 0.0, 0.1, "noise_per_sqrt_m");
  check(slip_per_m, 0.0, 10.0, "slip_per_m");
  check(slip_fraction, 0.0, 1.0, "slip_fraction");
}

OdometryErrors OdometryErrors::none() {
  OdometryErrors e;
  e.left_scale = e.right_scale = e.semi_axis_error = e.noise_per_sqrt_m = e.slip_per_m = 0.0;
  return e;
}

WheelTravel wheel_travel(double forward, double turn, double semi_axis) {
  return {forward - turn * semi_axis, forward + turn * semi_axis};
}

Pose2 drive(const Pose2& pose, const WheelTravel& t, double semi_axis) {
  const double ds = 0.5 * (t.left + t.right);
  const double dr = (t.right - t.left) / (2.0 * semi_axis);
  const double mid = pose.yaw() + 0.5 * dr;
  return {pose.x() + ds * std::cos(mid), pose.y() + ds * std::sin(mid), pose.yaw() + dr};
}

WheelEncoders::WheelEncoders(const OdometryErrors& errors, std::uint64_t seed)
    : e_(errors), rng_(seed) {
  e_.validate();
}

double WheelEncoders::measure(double truth, double scale) {
  double m = truth * (1.0 + scale);
  const double d = std::fabs(truth);
  if (d > 0 && e_.noise_per_sqrt_m > 0) {
    std::normal_distribution<double> n(0.0, e_.noise_per_sqrt_m * std::sqrt(d));
    m += n(rng_);
  }
  if (d > 0 && e_.slip_per_m > 0) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (u(rng_) < e_.slip_per_m * d) {
      m += truth * e_.slip_fraction;  // the wheel spun further than the robot moved
      ++slips_;
    }
  }
  return m;
}

WheelTravel WheelEncoders::step(const WheelTravel& truth) {
  cumulative_.left += measure(truth.left, e_.left_scale);
  cumulative_.right += measure(truth.right, e_.right_scale);
  return cumulative_;
}

}  // namespace lampnav::sim
