// The executor while the localizer does not know where the robot is: lost, it waits; ambiguous,
// it drives along the corridor to where the look-alike places differ (as far as the corridor runs
// in every one of them); between symmetry twins it stops the mission and says why.

#include "lampnav/navigation/executor.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"
#include "office.hpp"

namespace lampnav::navigation {
namespace {

using Office = test::NavOffice;
Stamp at(double s) { return test::at_s(s); }

fusion::LocalizerEstimate unsure(fusion::LocalizerMode mode, double t, const Pose2& p,
                                 std::vector<Pose2> others = {}) {
  fusion::LocalizerEstimate e;
  e.stamp = at(t);
  e.mode = mode;
  e.pose = p;
  e.hypotheses.push_back({p, Eigen::Matrix3d::Identity() * 1e-4, 0.6, nullptr});
  for (const auto& o : others)
    e.hypotheses.push_back({o, Eigen::Matrix3d::Identity() * 1e-4, 0.4 / others.size(), nullptr});
  return e;
}

Executor started(const Office& o, const Pose2& start) {
  Executor ex(o.map, 0.2);
  const auto commands = graph::parse_route_commands("go to Workshop");
  EXPECT_TRUE(ex.start(at(0), start, commands)) << ex.reason();
  return ex;
}

TEST(Executor, WaitsWhileLost) {
  const Office o;
  Executor ex = started(o, o.on_c1(2.0));
  const WheelSpeeds s = ex.step(unsure(fusion::LocalizerMode::lost, 1.0, o.on_c1(2.0)));
  EXPECT_EQ(s.left, 0.0);
  EXPECT_EQ(s.right, 0.0);
  EXPECT_EQ(ex.status(), ExecutorStatus::waiting);
}

TEST(Executor, DrivesAlongTheCorridorWhileAmbiguousThenStops) {
  const Office o;
  Executor ex = started(o, o.on_c1(2.0));
  // Two look-alike places, both facing along C1 (the twin 3 m further on).
  Pose2 p = o.on_c1(2.0);
  const WheelSpeeds s = ex.step(unsure(fusion::LocalizerMode::ambiguous, 1.0, p, {o.on_c1(5.0)}));
  EXPECT_GT(s.left, 0.1);
  EXPECT_NEAR(s.left, s.right, 0.05);  // straight on
  // Both places move alike; it stops by itself where the shorter corridor ahead (the twin's)
  // ends, and waits for the views there to differ.
  Pose2 twin = o.on_c1(5.0);
  double t = 1.0, driven = 0;
  WheelSpeeds w = s;
  for (int k = 0; k < 2800; ++k) {  // 56 s, within max_lost_s
    t += 0.02;
    const double v = 0.5 * (w.left + w.right), turn = (w.right - w.left) / 0.4;
    const Pose2 step(v * 0.02, 0.0, turn * 0.02);
    p = p * step;
    twin = twin * step;
    driven += std::abs(v) * 0.02;
    w = ex.step(unsure(fusion::LocalizerMode::ambiguous, t, p, {twin}));
  }
  const graph::Axis& a = *o.map.find_node("C1")->axis;
  EXPECT_NEAR(driven, a.length() - 5.0, 0.5);
  EXPECT_EQ(w.left + w.right, 0.0);
  EXPECT_EQ(ex.status(), ExecutorStatus::waiting);
}

TEST(Executor, StopsTheMissionBetweenSymmetryTwins) {
  const Office o;
  Executor ex = started(o, o.on_c1(2.0));
  fusion::LocalizerEstimate e =
      unsure(fusion::LocalizerMode::ambiguous, 1.0, o.on_c1(2.0), {o.on_c1(5.0)});
  e.undecidable = true;
  e.why = "the building looks the same from 2 places";
  const WheelSpeeds s = ex.step(e);
  EXPECT_EQ(s.left + s.right, 0.0);
  EXPECT_EQ(ex.status(), ExecutorStatus::failed);
  EXPECT_NE(ex.reason().find("cannot tell where it is"), std::string::npos) << ex.reason();
  EXPECT_NE(ex.reason().find("looks the same"), std::string::npos);
}

TEST(Executor, RefusesBadExploreOptions) {
  const Office o;
  ExecutorOptions bad;
  bad.explore_speed = 0;
  EXPECT_THROW(Executor(o.map, 0.2, bad), InputError);
  bad = {};
  bad.explore_m = -1;
  EXPECT_THROW(Executor(o.map, 0.2, bad), InputError);
}

}  // namespace
}  // namespace lampnav::navigation
