#pragma once
// The mapper's least-squares problem and its solve with Ceres Solver. Private to mapping/: Ceres
// stays out of every header.

#include <array>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"

namespace lampnav::mapping {

struct MappingProblem {
  std::vector<std::array<double, 3>> poses;   // keyframes (x, y, yaw), map frame: estimated
  std::vector<Pose2> odometry;                // dead reckoning at each keyframe
  std::vector<std::array<double, 2>> wheels;  // cumulative wheel travel (left, right) at each
  double semi_axis = 0.2;                     // m
  double wheel_difference = 0;                // estimated: right wheel 1 + d, left 1 - d
  // The building's axes (mod 90 degrees), estimated: a wing built at an angle to the rest has
  // its own (an "Atlanta world"). Each rectangular landmark is square to one of them (`axis_of`).
  std::vector<double> axes;
  std::vector<double> travel;                // m from the start at each keyframe
  std::vector<std::array<double, 4>> lamps;  // landmarks (x, y, z, yaw): estimated
  std::vector<bool> rectangle;               // per landmark
  std::vector<int> axis_of;                  // per landmark: its axis, or -1 (a disc)
  std::vector<int> kind;                     // per landmark: its kind
  // Per landmark: the shared height it hangs at. Its kind's (the group numbered as the kind)
  // until a solve finds it, with the lamps placed before and after it, hung apart from the
  // rest of its kind: then a group of its own (release_height). `group_height` is each group's
  // height as the last solve left it.
  std::vector<int> height_group;
  std::vector<double> group_height;
  // Lamps without an axis of their own (round, or square and taken for round) placed one after
  // the other along a straight stretch of the drive: the row's direction is square to `axis`, as
  // a rectangular lamp's own axis is. What holds the heading along a corridor of such lamps.
  struct Row {
    int from = 0, to = 0, axis = 0;
  };
  std::vector<Row> rows;
  struct Sighting {
    int keyframe = 0, lamp = 0;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // undistorted normalized
    double orientation = 0;                            // rad, image axis (rectangles)
  };
  std::vector<Sighting> sightings;
  // Keyframes the robot was carried to (lifted and put down): no odometry from the keyframe
  // before; held near where its part of the drive was placed until its lamps place it.
  struct Carry {
    std::size_t keyframe = 0;
    std::array<double, 3> placed{};  // x, y, yaw
  };
  std::vector<Carry> carries;
  bool carried_to(std::size_t keyframe) const {
    for (const Carry& c : carries)
      if (c.keyframe == keyframe) return true;
    return false;
  }
};

struct SolveReport {
  double seconds = 0;
  double rms_px = 0;  // reprojection RMS over the sightings, in pixels
  double chi2 = 0;    // the sum of the squared (robustified) residuals, in sigmas
  bool converged = false;
};

// Solves the problem in place; the first keyframe is held fixed (it is the map frame), a carry's
// keyframe by a prior of `carry_sigma_m` and `carry_sigma_yaw` (LampMapperOptions). With
// `first_free` > 0 only the keyframes from it on and the lamps they see move (their sightings
// from earlier keyframes anchor them); the wheels are held. The shared
// height of each kind of lamp is estimated by every solve. Each rectangular landmark, and each
// row's direction, is held square to its axis; an axis moves only in a whole solve, or in a
// window that holds all of its lamps.
SolveReport solve(MappingProblem& problem, const fusion::CeilingGeometry& geometry,
                  const LampMapperOptions& options, double focal_px, std::size_t first_free = 0);

// The axis a rectangular lamp first placed at `yaw` (or a row of round lamps in direction `yaw`)
// is square to: the nearest within `gate` rad (mod 90 degrees), or a new one at `yaw`. A corridor
// off the building's grid gets its own axis instead of being pulled onto the grid.
int axis_for(MappingProblem& problem, double yaw, double gate);

// A lamp or a row that has an axis: the problem's `rows[index]` or `lamps[index]`.
struct AxisMember {
  bool row = false;
  int index = 0;
};

// The lamp or row a solve left furthest off its axis (mod 90 degrees), when more than `trigger`
// rad and not among `tried`, with the members of its axis placed before and after it that lie off
// it the same way (at least a third of `trigger`): a corridor a few degrees off the grid whose
// first lamp the wheels placed within the gate of the grid's axis. Empty when none is.
std::vector<AxisMember> strained_members(const MappingProblem& problem, double trigger,
                                         const std::vector<AxisMember>& tried);

// Puts `group` on an axis of its own, at its first member's direction as solved (a lamp's yaw,
// a row's from one lamp to the other).
void leave_axis(MappingProblem& problem, const std::vector<AxisMember>& group);

// The landmark a solve left furthest from its group's shared height, when more than `trigger` m
// and not among `tried`, with the landmarks of its group placed before and after it that lie off
// the same way (at least a third of `trigger`): a corridor whose lamps hang higher or lower than
// the rest of their kind. Empty when none is.
std::vector<int> strained_heights(const MappingProblem& problem, double trigger,
                                  const std::vector<int>& tried);

// Gives `lamps` a shared height of their own, starting at their mean.
void release_height(MappingProblem& problem, const std::vector<int>& lamps);

}  // namespace lampnav::mapping
