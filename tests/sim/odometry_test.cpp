// Odometry noise statistics over many runs match the configured model.

#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/sim/odometry.hpp"
#include "lampnav_test.hpp"

namespace lampnav::sim {
namespace {

TEST(WheelEncoders, ScaleAndRandomErrorMatchTheModel) {
  OdometryErrors e = OdometryErrors::none();
  e.left_scale = 0.01;
  e.right_scale = -0.02;
  e.noise_per_sqrt_m = 0.003;
  const int runs = 2000;
  const double step = 0.01, distance = 4.0;
  double sum = 0, sum2 = 0, sum_r = 0;
  for (int k = 0; k < runs; ++k) {
    WheelEncoders enc(e, 1000 + k);
    for (int i = 0; i < static_cast<int>(distance / step); ++i) enc.step({step, step});
    const double err = enc.readings().left - distance * 1.01;
    sum += err;
    sum2 += err * err;
    sum_r += enc.readings().right;
  }
  const double mean = sum / runs, var = sum2 / runs - mean * mean;
  // Random error: variance sigma^2 * distance, zero mean; systematic: the scale.
  EXPECT_NEAR(mean, 0.0, 4 * 0.003 * std::sqrt(distance / runs));
  EXPECT_NEAR(std::sqrt(var), 0.003 * std::sqrt(distance), 0.003 * std::sqrt(distance) * 0.08);
  EXPECT_NEAR(sum_r / runs, distance * 0.98, 1e-3);
}

TEST(WheelEncoders, SlipsComeAtTheConfiguredRate) {
  OdometryErrors e = OdometryErrors::none();
  e.slip_per_m = 0.5;
  e.slip_fraction = 0.3;
  WheelEncoders enc(e, 7);
  const double step = 0.02;
  const int steps = 50000;  // 1 km per wheel
  for (int i = 0; i < steps; ++i) enc.step({step, step});
  const double expected = 2 * 0.5 * step * steps;  // both wheels
  EXPECT_NEAR(enc.slips(), expected, 4 * std::sqrt(expected));
  EXPECT_NEAR(enc.readings().left, step * steps * (1 + 0.5 * 0.3 * step), 1.0);
}

TEST(WheelEncoders, RefusesAbsurdErrors) {
  OdometryErrors e;
  e.left_scale = 0.5;
  EXPECT_THROW(WheelEncoders(e, 1), InputError);
}

TEST(Drive, WheelTravelRoundTrip) {
  const Pose2 p(1, 2, 0.5);
  const WheelTravel t = wheel_travel(0.3, 0.2, 0.2);
  const Pose2 q = drive(p, t, 0.2);
  EXPECT_NEAR(wrap_angle(q.yaw() - p.yaw()), 0.2, 1e-12);
  EXPECT_NEAR((q.translation() - p.translation()).norm(), 0.3, 1e-12);
}

}  // namespace
}  // namespace lampnav::sim
