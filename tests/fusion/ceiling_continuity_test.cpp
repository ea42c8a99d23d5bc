// The ceiling camera's continuity check on synthetic drives: a row of lamps down a corridor seen
// by robot.json's ceiling camera, floor bumps drawn at the pipeline's tilt, and lifts the wheels
// do not see.

#include <iostream>
#include <random>

#include "lampnav/fusion/ceiling_continuity.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kLampZ = 2.7, kSpacing = 2.25, kTilt = 0.0087;

CameraDescription ceiling_camera() {
  return *read_robot_description(test::source_path("maps/robots/pioneer.json"))
              .find_camera("ceiling_camera");
}

// A drive along +x at 0.5 m/s: wheel readings at 50 Hz, ceiling frames at 10 Hz. `truth(t)`
// gives where the robot is (a lift moves it; the wheels go on as if not).
class Drive {
 public:
  explicit Drive(std::uint32_t seed, double tilt = kTilt)
      : rng_(seed), tilt_(tilt), geometry_(ceiling_camera()), model_(camera_) {}

  // The frame at step k (0.1 s each), its lamps seen from `pose` with a bump; `lit(x)` says
  // whether the lamp at x lights.
  template <class Lit>
  std::vector<vision::LampDetection> frame(const Pose2& pose, Lit lit) {
    std::normal_distribution<double> bump(0, tilt_);
    const Vector2d tilt(bump(rng_), bump(rng_));
    std::vector<vision::LampDetection> lamps;
    for (double x = -kSpacing * 40; x < kSpacing * 200; x += kSpacing) {
      if (std::abs(x - pose.translation().x()) > 3 || !lit(x)) continue;
      auto n = geometry_.predict(pose, Vector3d(x, 0, kLampZ));
      if (!n) continue;
      *n += CeilingGeometry::tilt_jacobian(*n) * tilt;
      const Vector2d px = model_.pixel_of_normalized(*n);
      if (px.x() < 20 || px.y() < 20 || px.x() > model_.width() - 21 ||
          px.y() > model_.height() - 21)
        continue;
      vision::LampDetection d;
      d.centre = *n;
      lamps.push_back(d);
    }
    return lamps;
  }
  std::vector<vision::LampDetection> frame(const Pose2& pose) {
    return frame(pose, [](double) { return true; });
  }
  // The wheels' readings up to `t` (straight ahead at 0.5 m/s).
  void wheels_to(Stamp t, OdometryTrack& odometry) {
    while (wheel_t_ <= t) {
      odometry.add(wheel_t_, 0.01, 0.01);
      wheel_t_ += std::chrono::milliseconds(20);
    }
  }

 private:
  CameraDescription camera_ = ceiling_camera();
  std::mt19937 rng_;
  double tilt_;
  CeilingGeometry geometry_;
  vision::PinholeCamera model_;
  Stamp wheel_t_{};
};

Stamp at(int step) { return Stamp(std::chrono::milliseconds(100 * step)); }

TEST(CeilingContinuity, SteadyDriveUnderBumpsNeverBreaks) {
  // Five minutes (150 m) of bumps at the pipeline's tilt, with a stretch of dark frames and a
  // lamp that fails halfway and one that comes on: odd frames may happen, a move is never seen.
  Drive drive(1);
  OdometryTrack odometry(0.2);
  CeilingContinuity c(ceiling_camera(), kLampZ);
  int odd = 0, compared = 0, lamps = 0;
  for (int k = 0; k < 3000; ++k) {
    drive.wheels_to(at(k), odometry);
    const Pose2 pose(0.05 * k, 0, 0);
    if (k >= 1000 && k < 1010) {  // a second in the dark
      EXPECT_FALSE(c.frame(at(k), {}, odometry).compared);
      continue;
    }
    const auto seen = drive.frame(pose, [k](double x) {
      if (std::abs(x - 9 * kSpacing * 5) < 0.1 && k > 900) return false;    // fails
      if (std::abs(x - 9 * kSpacing * 10) < 0.1 && k < 2000) return false;  // comes on
      return true;
    });
    lamps += static_cast<int>(seen.size());
    const ContinuityVerdict v = c.frame(at(k), seen, odometry);
    EXPECT_FALSE(v.broken) << "frame " << k;
    odd += v.odd;
    compared += v.compared;
  }
  std::cout << odd << " odd frames of " << compared << " compared\n";
  EXPECT_GT(lamps, 3000);
  EXPECT_GT(compared, 2500);
  EXPECT_LE(odd, 15);  // none on this drive; 131 over the 103 wing drives of the docs
}

TEST(CeilingContinuity, LiftSeenInTwoFramesThatAgree) {
  // Lifted after frame 399, a lamp overhead (x = 20.25): it is gone from where the wheels put
  // it, and a lamp is where they put none.
  for (const double jump : {0.6, 1.0, 1.5, -0.5}) {
    Drive drive(2);
    OdometryTrack odometry(0.2);
    CeilingContinuity c(ceiling_camera(), kLampZ);
    std::optional<Stamp> seen_at, since, moved_by;
    for (int k = 300; k < 500; ++k) {
      drive.wheels_to(at(k), odometry);
      const Pose2 pose(0.05 * k + (k >= 400 ? jump : 0.0), 0, 0);
      const ContinuityVerdict v = c.frame(at(k), drive.frame(pose), odometry);
      if (v.broken && !seen_at) {
        seen_at = at(k);
        since = v.since;
        moved_by = v.moved_by;
        EXPECT_NE(v.why.find("the wheels did not"), std::string::npos);
      }
    }
    ASSERT_TRUE(seen_at) << "jump " << jump;
    EXPECT_EQ(*seen_at, at(401)) << "jump " << jump;   // the frame after the lift, confirmed
    EXPECT_EQ(*since, at(399)) << "jump " << jump;     // the last frame before it
    EXPECT_EQ(*moved_by, at(400)) << "jump " << jump;  // and the first after it
  }
  // Put down a lamp spacing on, the view is the one the wheels predict: no camera sees that.
  Drive drive(2);
  OdometryTrack odometry(0.2);
  CeilingContinuity c(ceiling_camera(), kLampZ);
  for (int k = 300; k < 500; ++k) {
    drive.wheels_to(at(k), odometry);
    const Pose2 pose(0.05 * k + (k >= 400 ? kSpacing : 0.0), 0, 0);
    EXPECT_FALSE(c.frame(at(k), drive.frame(pose), odometry).broken);
  }
}

TEST(CeilingContinuity, OneOddFrameIsNotAMove) {
  // A frame whose lamps are 0.6 m off (a detection gone wrong, a hard knock), then the drive as
  // before: odd, and no move.
  Drive drive(3);
  OdometryTrack odometry(0.2);
  CeilingContinuity c(ceiling_camera(), kLampZ);
  int odd = 0;
  for (int k = 300; k < 500; ++k) {
    drive.wheels_to(at(k), odometry);
    const Pose2 pose(0.05 * k + (k == 400 ? 0.6 : 0.0), 0, 0);
    const ContinuityVerdict v = c.frame(at(k), drive.frame(pose), odometry);
    EXPECT_FALSE(v.broken) << "frame " << k;
    odd += v.odd;
  }
  EXPECT_GE(odd, 1);
}

TEST(CeilingContinuity, LiftAfterDarkFramesIsSeen) {
  // Lifted in the dark (no lamp for two seconds while the wheels stand still), put down 0.9 m
  // on: the frames after are held against the last lit one.
  Drive drive(4);
  OdometryTrack odometry(0.2);
  CeilingContinuity c(ceiling_camera(), kLampZ);
  bool seen = false;
  for (int k = 0; k < 150; ++k) {
    drive.wheels_to(at(std::min(k, 80)), odometry);  // the wheels stop at frame 80
    const double x = 0.05 * std::min(k, 80) + (k >= 100 ? 0.9 : 0.0);
    const auto lamps =
        k > 80 && k < 100 ? std::vector<vision::LampDetection>{} : drive.frame(Pose2(x, 0, 0));
    const ContinuityVerdict v = c.frame(at(k), lamps, odometry);
    if (v.broken) {
      EXPECT_EQ(v.since, at(80));
      EXPECT_EQ(v.moved_by, at(100));
      seen = true;
    }
  }
  EXPECT_TRUE(seen);
}

TEST(CeilingContinuity, LearnsHowMuchTheFloorSwings) {
  // A minute's drive with the camera swung by each frame's own tilt: the lamps seen twice measure
  // it. As steady as configured, the configured spread stays; swung three and four times as
  // much, the spread learnt takes its place (and the gates widen: no move is seen once it is).
  for (const double swing : {0.5, 1.5, 2.0}) {
    const double tilt = swing * M_PI / 180;
    Drive drive(7, tilt);
    OdometryTrack odometry(0.2);
    CeilingContinuity c(ceiling_camera(), kLampZ);
    int broken = 0, learnt_at = -1;  // moves seen once the swing is learnt; the frame it was
    for (int k = 0; k < 600; ++k) {
      drive.wheels_to(at(k), odometry);
      const bool b = c.frame(at(k), drive.frame(Pose2(0.05 * k, 0, 0)), odometry).broken;
      if (learnt_at < 0 && c.learnt_tilt_sigma()) learnt_at = k;
      broken += b && learnt_at >= 0;
    }
    EXPECT_LE(learnt_at, 60) << swing;  // 50 lamps seen twice: within 6 s
    ASSERT_TRUE(c.learnt_tilt_sigma()) << swing;
    std::cout << "swing " << swing << " deg: learnt " << *c.learnt_tilt_sigma() * 180 / M_PI
              << " deg from " << c.tilt_samples() << " lamps\n";
    EXPECT_NEAR(*c.learnt_tilt_sigma(), tilt, 0.1 * tilt) << swing;
    EXPECT_EQ(c.tilt_samples(), CeilingContinuityOptions{}.tilt_window);
    if (swing < 1)
      EXPECT_EQ(c.tilt_sigma(), kTilt);
    else
      EXPECT_EQ(c.tilt_sigma(), *c.learnt_tilt_sigma());
    EXPECT_EQ(broken, 0) << swing;
    c.reset();  // a carry: the floor is the same
    EXPECT_EQ(c.tilt_samples(), CeilingContinuityOptions{}.tilt_window);
  }
  // Not learnt: the configured spread, whatever the floor does.
  CeilingContinuityOptions o;
  o.learn_tilt = false;
  Drive drive(7, 2 * M_PI / 180);
  OdometryTrack odometry(0.2);
  CeilingContinuity c(ceiling_camera(), kLampZ, o);
  for (int k = 0; k < 600; ++k) {
    drive.wheels_to(at(k), odometry);
    c.frame(at(k), drive.frame(Pose2(0.05 * k, 0, 0)), odometry);
  }
  EXPECT_FALSE(c.learnt_tilt_sigma());
  EXPECT_EQ(c.tilt_sigma(), kTilt);
}

TEST(CeilingContinuity, BadOptionsAreRefusedByName) {
  const auto refused = [](const CeilingContinuityOptions& o, double z = kLampZ) -> std::string {
    try {
      const CeilingContinuity c(ceiling_camera(), z, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  CeilingContinuityOptions o;
  EXPECT_EQ(refused(o), "");
  o.gate_sigmas = 0;
  EXPECT_THAT(refused(o), testing::HasSubstr("gate_sigmas"));
  o = {};
  o.margin = 0.5;
  EXPECT_THAT(refused(o), testing::HasSubstr("margin"));
  o = {};
  o.max_travel_m = std::nan("");
  EXPECT_THAT(refused(o), testing::HasSubstr("max_travel_m"));
  EXPECT_THAT(refused({}, 0.1), testing::HasSubstr("lamp_height"));  // below the camera
  o = {};
  o.tilt_min_samples = o.tilt_window + 1;
  EXPECT_THAT(refused(o), testing::HasSubstr("tilt_min_samples"));
  o = {};
  o.tilt_margin = 0.9;
  EXPECT_THAT(refused(o), testing::HasSubstr("tilt_margin"));
  o = {};
  o.max_tilt_sigma = 0.5 * o.tilt_sigma;
  EXPECT_THAT(refused(o), testing::HasSubstr("max_tilt_sigma"));
  o = {};
  o.tilt_match_m = -1;
  EXPECT_THAT(refused(o), testing::HasSubstr("tilt_match_m"));
}

}  // namespace
}  // namespace lampnav::fusion
