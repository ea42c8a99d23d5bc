// The kidnap monitor's rules and the odometry calibration, on synthetic evidence.

#include <iostream>
#include <random>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/chi_square.hpp"
#include "lampnav/fusion/kidnap_monitor.hpp"
#include "lampnav/fusion/odometry_calibration.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

CeilingEvidence frame(int unexplained, int missing = 0, int labelled = 1) {
  CeilingEvidence e;
  e.lamps_in_view = unexplained + labelled;
  e.labelled = labelled;
  e.unexplained = unexplained;
  e.expected_missing = missing;
  return e;
}

TEST(KidnapMonitor, LostAfterEnoughContradictingFramesInTheWindow) {
  KidnapMonitor m;  // 4 of 10
  for (int i = 0; i < 30; ++i) ASSERT_FALSE(m.ceiling(frame(0)));
  // Scattered contradictions (a stray reflection now and then) never add up to 4 of 10.
  for (int i = 0; i < 60; ++i) ASSERT_FALSE(m.ceiling(frame(i % 4 == 0 ? 1 : 0)));
  for (int i = 0; i < 10; ++i) ASSERT_FALSE(m.ceiling(frame(0)));
  ASSERT_FALSE(m.ceiling(frame(1)));
  ASSERT_FALSE(m.ceiling(frame(1)));
  ASSERT_FALSE(m.ceiling(frame(1)));
  const auto loss = m.ceiling(frame(1));
  ASSERT_TRUE(loss);
  EXPECT_EQ(loss->cause, ModeCause::ceiling_contradicts);
  EXPECT_NE(loss->why.find("contradict"), std::string::npos);
  EXPECT_EQ(m.counts().losses, 1u);
  // The window was reset: the next frame alone says nothing.
  EXPECT_FALSE(m.ceiling(frame(1)));
}

TEST(KidnapMonitor, MissingLampsAloneNeverLoseButSupportContradictions) {
  KidnapMonitor m;
  for (int i = 0; i < 200; ++i) ASSERT_FALSE(m.ceiling(frame(0, 2, 0)));  // a failed lamp
  m.reset();
  for (int i = 0; i < 4; ++i) ASSERT_FALSE(m.ceiling(frame(0, 1, 0)));
  ASSERT_FALSE(m.ceiling(frame(1, 0, 0)));
  const auto loss = m.ceiling(frame(1, 0, 0));  // 2 contradictions + 4 dark-where-lamps-should-be
  ASSERT_TRUE(loss);
  EXPECT_EQ(loss->cause, ModeCause::ceiling_contradicts);
  EXPECT_NE(loss->why.find("contradict the map"), std::string::npos) << loss->why;
}

TEST(KidnapMonitor, NormalisedInnovationWindow) {
  KidnapMonitor m;  // 8 measurements, p = 0.9999
  const double limit = chi_square_quantile(0.9999, 24);
  std::mt19937 rng(4);
  std::chi_squared_distribution<double> nis(3);
  for (int i = 0; i < 5000; ++i) ASSERT_FALSE(m.innovation(nis(rng))) << i;  // a consistent filter
  for (int i = 0; i < 7; ++i) ASSERT_FALSE(m.innovation(limit / 8 * 0.9));
  // One wild innovation is enough once the window's sum passes the quantile.
  const auto loss = m.innovation(limit);
  ASSERT_TRUE(loss);
  EXPECT_EQ(loss->cause, ModeCause::innovations_do_not_fit);
  EXPECT_EQ(m.counts().nis_alarms, 1u);
}

TEST(KidnapMonitor, OmniChecksInARowOrOneBeyondDoubt) {
  KidnapMonitor m;
  OmniCheckResult weak;
  weak.conclusive = true;
  weak.consistent = false;
  weak.lamp_side = true;
  weak.expected = 3;
  weak.matched = 1;
  weak.blobs = 3;
  weak.explained_blobs = 2;
  OmniCheckResult fine = weak;
  fine.consistent = true;
  EXPECT_FALSE(m.omni(weak));
  EXPECT_FALSE(m.omni(fine));  // a consistent check breaks the run
  EXPECT_FALSE(m.omni(weak));
  const auto loss = m.omni(weak);
  ASSERT_TRUE(loss);
  EXPECT_EQ(loss->cause, ModeCause::omni_disagrees);
  EXPECT_STREQ(to_string(loss->cause), "omni_disagrees");
  OmniCheckResult strong = weak;
  strong.blob_side = true;
  strong.blobs = 12;
  strong.explained_blobs = 1;
  strong.expected = 6;
  strong.matched = 0;
  EXPECT_TRUE(m.omni(strong));
  OmniCheckResult unsure;
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(m.omni(unsure));  // inconclusive: no vote
  KidnapMonitorOptions bad;
  bad.contradicting_frames = 20;
  EXPECT_THROW(KidnapMonitor{bad}, InputError);
}

// Wheels that turn 1 degree per metre when driving straight, and a track 1 % wider than told:
// the calibration learns both from noisy heading measurements.
TEST(OdometryCalibration, LearnsDriftAndTurnScale) {
  OdometryCalibration cal;
  const double a = 0.2, drift = -0.0175, scale = 0.01;
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0, 0.002);
  double yaw = 0;
  Stamp t = stamp_from_seconds(0);
  for (int i = 0; i < 6000; ++i) {
    t += std::chrono::milliseconds(20);
    const double ds = 0.01, turn = (i / 500) % 2 ? 0.01 : 0.0;  // straight, then arcs
    // The wheels report a heading change that misses the drift and the scale.
    const double reported = (turn - drift * ds) * (1 - scale);
    cal.wheels(t, ds - a * reported, ds + a * reported);
    yaw = wrap_angle(yaw + turn);
    if (i % 5 == 0) cal.heading(t, wrap_angle(yaw + noise(rng)), 0.002 * 0.002);
  }
  EXPECT_GT(cal.pairs(), 1000);
  EXPECT_NEAR(cal.yaw_drift_per_m(), drift, 0.001);
  EXPECT_NEAR(cal.turn_scale(), scale, 0.003);
  // Corrected increments give back the true heading change.
  const double reported = (0.01 - drift * 0.01) * (1 - scale);
  const auto [l, r] = cal.correct(0.01 - a * reported, 0.01 + a * reported);
  EXPECT_NEAR((r - l) / (2 * a), 0.01, 1e-4);
  EXPECT_NEAR((r + l) / 2, 0.01, 1e-12);
}

// Wheels that read every metre 3 % long (soft tyres, a wheel radius off) on a way of straights
// and arcs, poses measured with 1 cm and 0.06 degrees of noise: the calibration learns the travel's
// scale, corrects the increments to the true travel, and a measurement 2 m off (a wrong fix, a
// slip) is left out of the fit.
TEST(OdometryCalibration, LearnsTheTravelScale) {
  const double a = 0.2, long_by = 0.03;
  auto drive = [&](OdometryCalibration& cal, bool with_jump) {
    std::mt19937 rng(9);
    std::normal_distribution<double> noise(0, 0.01);
    double x = 0, y = 0, yaw = 0;
    Stamp t = stamp_from_seconds(0);
    for (int i = 0; i < 6000; ++i) {
      t += std::chrono::milliseconds(20);
      const double ds = 0.01, turn = (i / 400) % 2 ? 0.004 : 0.0;
      x += ds * std::cos(yaw + turn / 2);
      y += ds * std::sin(yaw + turn / 2);
      yaw = wrap_angle(yaw + turn);
      const double l = (ds - a * turn) * (1 + long_by), r = (ds + a * turn) * (1 + long_by);
      cal.wheels(t, l, r);
      if (i % 5 != 0) continue;
      // As the localizer gives them: a pose's heading (which teaches the turns' 3 % too) and
      // its position.
      const double jump = with_jump && i == 3000 ? 2.0 : 0.0;
      cal.heading(t, wrap_angle(yaw + 0.1 * noise(rng)), 1e-6);
      cal.position(t, x + noise(rng) + jump, y + noise(rng), 1e-4, 0, 1e-4);
    }
  };
  OdometryCalibration cal;
  drive(cal, true);
  std::cout << "travel scale " << cal.travel_scale() << " (truth " << 1 / (1 + long_by) - 1 << "), "
            << cal.travel_pairs() << " pairs, " << cal.travel_outliers() << " left out\n";
  EXPECT_GT(cal.travel_pairs(), 1000);
  EXPECT_GE(cal.travel_outliers(), 1);  // the jump, with the pairs that span it
  EXPECT_LE(cal.travel_outliers(), 60);
  EXPECT_NEAR(cal.travel_scale(), 1 / (1 + long_by) - 1, 0.002);
  const auto [l, r] = cal.correct(0.01 * (1 + long_by), 0.01 * (1 + long_by));
  EXPECT_NEAR((l + r) / 2, 0.01, 0.00002);
  EXPECT_NEAR((r - l) / (2 * a), 0.0, 1e-4);  // a straight stays (nearly) straight
  // Told not to learn it, or given no positions, it keeps the wheels' travel.
  OdometryCalibrationOptions off;
  off.learn_travel = false;
  OdometryCalibration kept(off);
  drive(kept, false);
  EXPECT_EQ(kept.travel_pairs(), 0);
  EXPECT_EQ(kept.travel_scale(), 0.0);
  OdometryCalibrationOptions bad;
  bad.min_scale_travel = 10;  // beyond max_travel: no pair could ever form
  EXPECT_THROW(OdometryCalibration{bad}, InputError);
}

}  // namespace
}  // namespace lampnav::fusion
