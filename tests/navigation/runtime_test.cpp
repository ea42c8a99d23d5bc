// The runtime loop on its own, with a scripted robot: wheels that turn as the loop commands (an
// ideal differential drive, so dead reckoning is the truth), frames that are not images of their
// camera, route commands given while running. No rendering, no log.

#include "lampnav/navigation/runtime.hpp"

#include <deque>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"
#include "office.hpp"

namespace lampnav::navigation {
namespace {

Stamp at(double s) { return test::at_s(s); }

// An ideal differential drive read at 50 Hz: the wheel speeds the loop set are held for 20 ms and
// integrated exactly; inputs queued by the test come out first, in their order.
class ScriptedRobot : public Robot {
 public:
  ScriptedRobot(const Pose2& start, double semi_axis, double seconds)
      : pose_(start), semi_axis_(semi_axis), steps_(static_cast<int>(seconds * 50)) {}
  void set_wheel_speeds(double left, double right) override {
    left_speed_ = left;
    right_speed_ = right;
    ++commands_;
    if (left > 0 && right > 0) ++forward_;
  }
  std::optional<RobotInput> next() override {
    if (!queued_.empty()) {
      RobotInput in = std::move(queued_.front());
      queued_.pop_front();
      return in;
    }
    if (step_ >= steps_) return std::nullopt;
    ++step_;
    const double dl = left_speed_ * 0.02, dr = right_speed_ * 0.02;
    const fusion::StateVector x =
        fusion::predict_motion({pose_.x(), pose_.y(), pose_.yaw()}, dl, dr, semi_axis_);
    pose_ = Pose2(x(0), x(1), x(2));
    left_ += dl;
    right_ += dr;
    return WheelInput{now(), left_, right_};
  }
  void queue(RobotInput in) { queued_.push_back(std::move(in)); }
  Stamp now() const { return at(1.0 + step_ * 0.02); }
  const Pose2& pose() const { return pose_; }
  int commands() const { return commands_; }
  int forward() const { return forward_; }

 private:
  Pose2 pose_;
  double semi_axis_;
  int steps_, step_ = 0;
  double left_speed_ = 0, right_speed_ = 0, left_ = 0, right_ = 0;
  int commands_ = 0, forward_ = 0;
  std::deque<RobotInput> queued_;
};

struct Recorder : RuntimeObserver {
  int estimates = 0;
  std::vector<std::string> refused, commands, pose_estimates;
  void on_pose_estimate(const PoseInput&, const std::string& why) override {
    pose_estimates.push_back(why.empty() ? "taken" : why);
  }
  void on_estimate(const fusion::LocalizerEstimate&) override { ++estimates; }
  void on_refused(const FrameInput&, const std::string& why) override { refused.push_back(why); }
  void on_command(const CommandInput& c, const std::string& why) override {
    commands.push_back(c.text + (why.empty() ? ": taken" : ": " + why));
  }
};

using Office = test::NavOffice;

// With the start given and wheels that do what they are told, the loop drives the route to its
// goal on dead reckoning alone, one estimate per wheel reading.
TEST(Runtime, DrivesTheRouteOnWheelsAloneWhenTheyAreExact) {
  const Office o;
  const Pose2 start = o.on_c1(1.0);
  ScriptedRobot robot(start, o.robot.semi_axis, 120.0);
  Runtime rt(o.map, o.robot);
  Recorder rec;
  const RunOutcome out = rt.run(robot, start, graph::parse_route_commands("go to Workshop"), &rec);
  ASSERT_EQ(out.status, ExecutorStatus::arrived) << out.reason;
  EXPECT_EQ(static_cast<int>(out.wheel_readings), rec.estimates);
  EXPECT_GT(robot.forward(), 100);
  // Arrived where the route ends: in the Workshop's region.
  const graph::Node* goal = o.map.find_node("Workshop");
  const auto* in = o.map.node_containing(robot.pose().translation());
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->id, goal->id);
  // It stopped there: the loop ended with the mission, before the robot's input ran out.
  EXPECT_LT(out.duration_s(), 119.0);
}

// A frame of the wrong size is refused and said, a bad command is refused naming the word, a good
// one becomes the mission; when the input ends before it arrives, the loop says so.
TEST(Runtime, RefusesBadFramesAndCommandsAndSaysWhyItStopped) {
  const Office o;
  const Pose2 start = o.on_c1(1.0);
  ScriptedRobot robot(start, o.robot.semi_axis, 2.0);
  FrameInput small;
  small.camera = CameraRole::ceiling;
  small.capture = small.arrival = at(1.0);
  small.image = Image8(10, 10, 0);
  robot.queue(WheelInput{at(0.98), 0, 0});
  robot.queue(small);
  robot.queue(CommandInput{at(1.0), "turn sideways at the moon"});
  robot.queue(CommandInput{at(1.0), "go to Workshop"});
  Runtime rt(o.map, o.robot);
  Recorder rec;
  const RunOutcome out = rt.run(robot, start, {}, &rec);
  EXPECT_EQ(out.refused_frames, 1u);
  ASSERT_EQ(rec.refused.size(), 1u);
  EXPECT_NE(rec.refused[0].find("10"), std::string::npos) << rec.refused[0];
  EXPECT_EQ(out.commands, 1u);  // taken
  EXPECT_EQ(out.refused_commands, 1u);
  ASSERT_EQ(rec.commands.size(), 2u);
  EXPECT_NE(rec.commands[0].find("sideways"), std::string::npos) << rec.commands[0];
  EXPECT_NE(rec.commands[1].find(": taken"), std::string::npos) << rec.commands[1];
  EXPECT_GT(robot.forward(), 10);  // on its way
  EXPECT_NE(out.status, ExecutorStatus::arrived);
  EXPECT_EQ(out.reason, "the robot stopped giving input");
}

TEST(Runtime, RefusesBadOptions) {
  const Office o;
  RuntimeOptions bad;
  bad.max_duration_s = -1;
  EXPECT_THROW(Runtime(o.map, o.robot, bad), InputError);
}

// No start and no camera: the robot is never found and the mission never starts, until an
// operator says where it is ("2D Pose Estimate"). Then the filter starts there, relocalized (the
// cameras would confirm it) and the route is driven. A second estimate moves the pose at once.
TEST(Runtime, AnOperatorsPoseEstimateIsTakenAsAFix) {
  const Office o;
  const Pose2 start = o.on_c1(1.0);
  const Eigen::Matrix3d P = Eigen::Vector3d(0.25, 0.25, 0.0685).asDiagonal();
  {
    ScriptedRobot robot(start, o.robot.semi_axis, 5.0);
    Runtime rt(o.map, o.robot);
    const RunOutcome out =
        rt.run(robot, std::nullopt, graph::parse_route_commands("go to Workshop"));
    EXPECT_EQ(robot.forward(), 0) << "drove without knowing where it was";
    EXPECT_FALSE(rt.localizer().initialized());
    EXPECT_EQ(out.pose_estimates, 0u);
  }
  ScriptedRobot robot(start, o.robot.semi_axis, 120.0);
  robot.queue(WheelInput{at(0.98), 0, 0});
  robot.queue(PoseInput{at(0.98), start, P});
  Runtime rt(o.map, o.robot);
  Recorder rec;
  const RunOutcome out =
      rt.run(robot, std::nullopt, graph::parse_route_commands("go to Workshop"), &rec);
  EXPECT_EQ(out.pose_estimates, 1u);
  ASSERT_EQ(rec.pose_estimates, std::vector<std::string>{"taken"});
  ASSERT_EQ(out.status, ExecutorStatus::arrived) << out.reason;
  EXPECT_EQ(rt.localizer().estimate().mode, fusion::LocalizerMode::relocalized);
  const graph::Node* in = o.map.node_containing(robot.pose().translation());
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->id, o.map.find_node("Workshop")->id);

  // Tracking, told it is elsewhere: the estimate is there at once.
  ScriptedRobot moved(start, o.robot.semi_axis, 1.0);
  const Pose2 there(start.x() + 3.0, start.y(), start.yaw());
  moved.queue(WheelInput{at(0.98), 0, 0});
  moved.queue(WheelInput{at(0.99), 0, 0});
  moved.queue(PoseInput{at(0.99), there, P});
  Runtime rt2(o.map, o.robot);
  rt2.run(moved, start, {});
  const fusion::LocalizerEstimate e = rt2.localizer().estimate();
  EXPECT_NEAR((e.pose.translation() - there.translation()).norm(), 0.0, 1e-6);
  EXPECT_EQ(e.mode, fusion::LocalizerMode::relocalized);
}

}  // namespace
}  // namespace lampnav::navigation
