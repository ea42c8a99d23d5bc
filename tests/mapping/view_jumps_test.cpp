// Where a drive's ceiling view jumps (the robot carried): found where a lamp appears in the middle
// of the view, or cut by the border further in than it could have entered, with none of the lamps
// before still in it; and nowhere else: not while driving under lamps or turning on the spot, not
// for one bad frame, not for a lamp that goes out or comes on.

#include "view_jumps.hpp"

#include <gtest/gtest.h>

#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

const CameraDescription& camera() {
  static const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  return *robot.find_camera("ceiling_camera");
}

vision::LampDetection lamp(double x, double y, vision::LampView view = vision::LampView::full) {
  const CameraDescription& c = camera();
  vision::LampDetection d;
  d.view = view;
  d.centre = {x, y};
  d.centre_px = {c.pinhole.cx + c.pinhole.fx * x, c.pinhole.cy + c.pinhole.fy * y};
  return d;
}

// A drive at 0.5 m/s, frames at 10 Hz, the lamps of each frame given; or turning on the spot,
// each wheel `spin` m a frame (on a 0.2 m semi-axis).
struct Drive {
  std::vector<std::vector<vision::LampDetection>> lamps;
  double spin = 0;
  double speed = 0.05;  // m a frame, when not turning
  std::vector<ViewFrame> frames() const {
    std::vector<ViewFrame> out(lamps.size());
    for (std::size_t i = 0; i < lamps.size(); ++i) {
      out[i].stamp = stamp_from_seconds(0.1 * i);
      out[i].wheels = spin > 0 ? Pose2(0, 0, spin * i / 0.2) : Pose2(speed * i, 0, 0);
      out[i].lamps = &lamps[i];
    }
    return out;
  }
};

// Lamps 2.25 m apart under a 2.4 m ceiling stream across the view (0.02 normalized a frame):
// each enters cut, crosses whole, leaves cut.
Drive under_a_row_of_lamps(int frames) {
  Drive d;
  for (int i = 0; i < frames; ++i) {
    std::vector<vision::LampDetection> f;
    for (int k = 0; k < 4; ++k) {
      const double x = 0.6 - 0.02 * i + 0.94 * k;
      if (std::abs(x) < 0.3)
        f.push_back(lamp(x, 0.0));
      else if (std::abs(x) < 0.55)
        f.push_back(lamp(x, 0.0, vision::LampView::completed));
    }
    d.lamps.push_back(f);
  }
  return d;
}

TEST(ViewJumps, DrivingUnderLampsIsNoJump) {
  const Drive d = under_a_row_of_lamps(200);
  EXPECT_TRUE(view_jumps(d.frames(), camera()).empty());
}

TEST(ViewJumps, ALampInTheMiddleWhereNoneWasComingIsAJump) {
  Drive d = under_a_row_of_lamps(60);
  // Carried at frame 60: put down under another lamp, facing the other way; carried again at
  // frame 80, under a lamp off to the side.
  for (int i = 0; i < 20; ++i) d.lamps.push_back({lamp(0.1 - 0.02 * i, 0.01)});
  for (int i = 0; i < 20; ++i) d.lamps.push_back({lamp(0.1 - 0.02 * i, -0.2)});
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{60, 80}));
}

// Put down where the only lamp in view is cut by the border: it reaches 100 px in (a third of
// the normalized plane), where no lamp entering since the last frame could be.
TEST(ViewJumps, ALampCutByTheBorderFurtherInThanItCouldHaveComeIsAJump) {
  Drive d = under_a_row_of_lamps(60);
  for (int i = 0; i < 20; ++i) {
    vision::LampDetection cut = lamp(-0.45 - 0.02 * i, 0.15, vision::LampView::completed);
    cut.bbox = {0, 150, 100 - 6 * i, 175};
    d.lamps.push_back({cut});
  }
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{60}));
}

// Turning on the spot at 1.5 rad/s: the ceiling turns about the view's centre, and lamps far out
// move 0.07 a frame, more than the gate. The turn is predicted (the camera is 0.1 m ahead of the
// axis, the lamps 2.4 m above it): no jump.
TEST(ViewJumps, TurningOnTheSpotIsNoJump) {
  Drive d;
  d.spin = 0.03;  // m a frame each wheel, 0.15 rad a frame on a 0.2 m semi-axis
  const Eigen::Vector2d mount(0.1, 0.0);
  for (int i = 0; i < 60; ++i) {
    const double t = -0.15 * i, c = std::cos(t), s = std::sin(t);
    std::vector<vision::LampDetection> f;
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.45, 0.1), Eigen::Vector2d(-0.2, -0.4)}) {
      // The ceiling point p (normalized, at the start) seen after turning by -t.
      const Eigen::Vector2d q = p + mount / 2.4;
      const Eigen::Vector2d r(c * q.x() - s * q.y(), s * q.x() + c * q.y());
      f.push_back(lamp(r.x() - mount.x() / 2.4, r.y() - mount.y() / 2.4));
    }
    d.lamps.push_back(f);
  }
  EXPECT_TRUE(view_jumps(d.frames(), camera()).empty());
}

// Carried at frame 80, under a lamp seen whole since frame 62: the lamp jumps 0.08 further along
// the drive than the wheels take it. That is within the gate of the motion for a lamp of any
// height from 1 m up, so the frames after would pass as the old view; but the lamp's height is
// known from its views before (2.5 m), and at that height it is 0.08 off.
TEST(ViewJumps, ALampsHeightFromItsViewsNarrowsWhereItCanGo) {
  Drive d = under_a_row_of_lamps(120);
  for (int i = 80; i < 120; ++i) {
    const Drive shifted = under_a_row_of_lamps(i + 5);
    d.lamps[i] = shifted.lamps[i + 4];  // 4 frames on: 0.08 further along
  }
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{80}));
}

// Put down at frame 80 where the lamp lies 0.045 (11 cm) to the side of where the wheels take
// it: inside the gate of one frame, so the lamp is followed across; but its place on the
// ceiling, averaged over its views on each side, moved. (A move along the drive is harder: over
// a few views it looks much like the lamp a little lower.)
TEST(ViewJumps, ALookAlikePlaceCloserThanTheGateIsFoundByTheLampsPlaces) {
  Drive d = under_a_row_of_lamps(120);
  for (int i = 80; i < 120; ++i)
    for (vision::LampDetection& l : d.lamps[i]) l = lamp(l.centre.x(), 0.045, l.view);
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{80}));
}

// Put down where a whole lamp lies in the middle of the view, with a lamp at the border where
// one of the two before was: two views cut by the border are no sign that the view stayed.
TEST(ViewJumps, ALampCutByTheBorderInBothViewsDoesNotHoldTheViewTogether) {
  Drive d;
  d.speed = 0;  // standing still
  for (int i = 0; i < 40; ++i)
    d.lamps.push_back({lamp(0.5, 0.0, vision::LampView::completed),
                       lamp(-0.45, 0.0, vision::LampView::completed)});
  for (int i = 0; i < 20; ++i)
    d.lamps.push_back({lamp(0.48, 0.0, vision::LampView::partial), lamp(-0.1, 0.0)});
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{40}));
}

// A bumpy floor: two frames in every ten swing the view 0.07 sideways, more than the gate. The
// drive's lamps of known height then lie off their predicted places by that much in a fifth of
// their views, and the gate widens to take it: no jump, but the carry at frame 300.
TEST(ViewJumps, ABumpyFloorWidensTheGate) {
  Drive d = under_a_row_of_lamps(300);
  for (int i = 0; i < 50; ++i) d.lamps.push_back({lamp(0.2 - 0.02 * i, -0.25)});
  for (int i = 0; i < 350; ++i)
    if (i % 10 == 3 || i % 10 == 4)
      for (vision::LampDetection& l : d.lamps[i])
        l = lamp(l.centre.x(), l.centre.y() + 0.07, l.view);
  EXPECT_EQ(view_jumps(d.frames(), camera()), (std::vector<std::size_t>{300}));
}

TEST(ViewJumps, OneBadFrameOrALampGoingOutOrComingOnIsNoJump) {
  Drive glitch = under_a_row_of_lamps(120);
  glitch.lamps[60] = {lamp(0.05, 0.2)};  // one frame: a reflection, the lamps missed
  EXPECT_TRUE(view_jumps(glitch.frames(), camera()).empty());

  Drive out = under_a_row_of_lamps(120);
  for (int i = 60; i < 120; ++i) out.lamps[i].clear();  // the lamp overhead fails, then dark
  EXPECT_TRUE(view_jumps(out.frames(), camera()).empty());

  Drive on = under_a_row_of_lamps(120);
  for (int i = 60; i < 120; ++i) {  // one comes on, and the drive takes it across the view
    const double x = 0.2 - 0.02 * (i - 60);
    if (std::abs(x) < 0.3)
      on.lamps[i].push_back(lamp(x, 0.3));
    else if (std::abs(x) < 0.55)
      on.lamps[i].push_back(lamp(x, 0.3, vision::LampView::completed));
  }
  EXPECT_TRUE(view_jumps(on.frames(), camera()).empty());
}

}  // namespace
}  // namespace lampnav::mapping
