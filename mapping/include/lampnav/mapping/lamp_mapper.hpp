#pragma once
// Lamp SLAM from a drive: robot poses at keyframes of the ceiling camera and the lamps as
// landmarks (x, y, height, yaw), estimated together by nonlinear least squares (Ceres Solver) from
// the wheels and the ceiling camera's lamp detections. The map frame is the robot's start pose.
//
// Front end: a keyframe every `keyframe_m` of travel; each lamp the detector saw whole is first
// followed from the last keyframe across the image (`track_gate`), whatever its height; else it
// is placed on the ceiling from the current estimate of the pose and joins the nearest landmark
// of its kind (`kinds`) within `gate_m`, or starts a new one, at the median solved height of its
// kind (`height_guess_m` before the first solve). The pose estimate is the last keyframe's, as
// the last solve left it, moved by the wheels with the difference between them that the last
// whole solve estimated: a lamp seen again after a loop is placed with the loop's drift only
// since then, and the estimate does not curve with the wheels between solves.
// Back end (src/back_end.cpp): odometry factors between keyframes from the wheel noise model,
// reprojection factors on the lamps' centres in undistorted normalized coordinates (the detector's
// output), and orientation factors for rectangular lamps; a Huber loss on the camera terms. The
// problem is solved again every `solve_every_m` of travel (the last `window_m` of the drive, and
// so all of it over the first `window_m`; all of it when a loop has closed, at most every
// `whole_every_m`) and at the end.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::mapping {

struct LampMapperOptions {
  double gate_m = 0.5;  // a lamp joins a landmark this close on the ceiling
  // A lamp the last keyframe saw is followed across the image: its predicted centre within this
  // (normalized image units; 0.08 is 24 px at a focal length of 300 px).
  double track_gate = 0.08;
  double height_guess_m = 2.7;  // a new lamp's height above the floor before the first solve
  double keyframe_m = 0.1;      // travel (m, the turning arc counted) between keyframes
  double solve_every_m = 5.0;   // travel between two solves
  double window_m = 30.0;       // a solve moves only the last this much of the drive, unless
                                // a loop closed since the last whole solve and that was at
  double whole_every_m = 50.0;  // least this far back (then all of it)
  // A lamp centre's noise (px, at the camera's focal length): the detector's fraction of a pixel
  // and the floor's bumps, which tilt the camera by half a degree (2 cm on the ceiling).
  double pixel_sigma_px = 3.0;
  double orientation_sigma = 0.005;        // rad, a rectangular lamp's axis in the image
  double odometry_sigma_per_m = 0.004;     // m per sqrt(m) of travel, each of x and y
  double odometry_yaw_sigma_per_m = 0.01;  // rad per sqrt(m) of travel
  double wheel_scale_sigma = 0.01;         // prior on the wheels' relative scale difference (at 0)
  // Rectangular lamps mounted square to the building (their axes 90 degrees apart): holds the
  // heading along corridors driven once. A new lamp joins the axis its first yaw (from the
  // wheels since the last solve) is within `square_gate_rad` of (mod 90 degrees), or starts one
  // of its own: a wing or corridor built at an angle to the rest keeps its angle, and its lamps
  // are held square to each other. The gate is wide for the wheels' drift between solves (the
  // simulated wheels' 0.7 % difference turns the heading 1.2 degrees a metre), so a corridor
  // less than that far off the grid is taken as square.
  bool square_lamps = true;
  double square_sigma = 0.01;    // rad, how square
  double square_gate_rad = 0.2;  // rad, how far off an axis a lamp may first be placed and join it
  // A corridor a few degrees off the grid, inside the gate, is pulled square by the prior, and
  // the camera's sightings of its lamps turn the poses that saw them. A lamp or row a solve leaves
  // more than `square_release_rad` off its axis is tried on an axis of its own, with those placed
  // before and after it that lie off it the same way, and kept there when the solve's chi-square
  // falls by at least `square_release_chi2` (the new axis is one parameter; on ten 10-minute
  // drives of square lamps it fell by 11 at most). pi/4: never.
  double square_release_rad = 0.015;
  double square_release_chi2 = 16;
  // Round lamps (and square panels, which the kinds' probe takes for round) have no axis: two of
  // one kind placed one after the other within `row_max_m`, the drive turning less than
  // `row_max_turn_rad` between them and the second ahead of the first along it (within
  // `square_gate_rad`), are a row, whose direction joins an axis as a rectangular lamp's does
  // (Huber beyond `row_sigma`: a lamp hung a centimetre off its row's line). `row_max_m` is wide
  // enough for lamps 4.5 to 6.75 m apart, or a row with a lamp failed (at 4 m, the office's discs
  // 4.5 m apart made no row and its corridors bent by 25 cm).
  double row_sigma = 0.005;       // rad
  double row_max_m = 8.0;         // m between the two lamps
  double row_max_turn_rad = 0.1;  // rad the drive turned between placing them
  // Lamps of one kind hang at one height, within this (m; Huber beyond it). 0: each its own.
  double shared_height_sigma = 0.01;
  // Unless a solve leaves a lamp more than `height_release_m` off its kind's height: it is tried
  // at a height of its own, with the lamps of its kind placed before and after it that lie off
  // it the same way, and kept there when the solve's chi-square falls by at least
  // `height_release_chi2` (a corridor under a lower or higher ceiling). 0: never.
  double height_release_m = 0.04;
  double height_release_chi2 = 16;
  // Lamps of several kinds under one ceiling: each kind's height held to the most common kind's
  // within `kind_tie_sigma` while the two are at most `kind_tie_max_m` apart (a Tukey loss:
  // kinds hung further apart, a hall's high lamps and a gallery's low ones, go free). A kind with
  // one or two lamps, seen from one side at a drive's end, then takes the ceiling's height.
  // 0: each kind its own.
  double kind_tie_sigma = 0.01;
  double kind_tie_max_m = 0.15;
  double huber_sigmas = 3.0;  // the camera terms' loss turns linear beyond this many sigmas
  // A landmark is kept when seen at enough keyframes to place it within placed_sigma_m (each
  // sighting places it to its height above the camera times pixel_sigma_px over the focal
  // length), at least min_sightings_near and never more than min_sightings needed: under an
  // office ceiling 3 (a corridor lamp seen whole only from a corner's turn, left out at 5, made
  // a replay under it call the map contradicted), under one 8 m high 5 (one seen 3 times was
  // 8 cm off). Fewer is a glint.
  int min_sightings = 5;
  int min_sightings_near = 3;
  double placed_sigma_m = 0.015;
  double merge_m = 0.3;     // landmarks of one kind this close after solving are one lamp
  int max_iterations = 50;  // per solve
  // A lamp seen again after 20 m away joins its landmark (closing the loop). Off: it starts a
  // new one, as mapping without loop closure would (for comparison: docs/mapping.md).
  bool close_loops = true;
  // A carry's keyframe is held where its part of the drive was placed, within these, until the
  // lamps both parts saw tie it to the rest (`LampMapper::carried`).
  double carry_sigma_m = 0.1;
  double carry_sigma_yaw = 0.03;  // rad
  // The kinds of lamp the detector looks for, seen from unit distance (map_build learns them):
  // a lamp seen whole is of the nearest kind of its shape, joins only landmarks of its kind, and
  // shares its kind's height. Empty: two kinds, long lamps and round ones.
  std::vector<vision::LampShapePrior> kinds;
  void validate() const;  // throws InputError naming the field
};

// A lamp of the built map, in the map frame (the drive's start).
struct MappedLamp {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // centre; z above the floor
  double yaw = 0;                                 // rad, the long axis (rectangles)
  graph::LampShape shape = graph::LampShape::rectangle;
  double length = 0, width = 0;  // m, the median of the sightings' sizes
  int sightings = 0;             // keyframes that saw it

  // As a lamp of a map, named `id`, moved by `motion` (from the drive's frame into another).
  graph::Lamp as_map_lamp(LampId id, const Pose2& motion = Pose2::identity()) const;
};

struct KeyframePose {
  Stamp stamp;
  Pose2 pose;           // optimized, map frame
  Pose2 dead_reckoned;  // the wheels alone, from the same start
  double travel_m = 0;  // from the start
};

struct MappingResult {
  std::vector<MappedLamp> lamps;
  std::vector<KeyframePose> keyframes;
  std::size_t sightings = 0;            // lamp observations in the problem
  std::size_t revisits = 0;             // sightings of a landmark after 20 m away from it
  std::size_t dropped = 0, merged = 0;  // landmarks dropped (too few sightings) and merged
  int solves = 0;
  double solve_seconds = 0;  // in Ceres, all solves
  double final_rms_px = 0;   // reprojection RMS of the last solve
};

class LampMapper {
 public:
  // The robot's `ceiling_camera` (its mount gives the geometry, fx the pixel scale) and wheel
  // base; throws InputError for bad options or a robot without a ceiling camera.
  LampMapper(const RobotDescription& robot, const LampMapperOptions& options = {});
  ~LampMapper();
  LampMapper(LampMapper&&) noexcept;

  // Cumulative travel of each wheel (m), read at `stamp`, in time order.
  void wheels(Stamp stamp, double left, double right);
  // The lamps the detector found in a ceiling frame captured at `stamp` (at most as late as the
  // wheels' last reading). Only lamps seen whole are used.
  void ceiling(Stamp stamp, const std::vector<vision::LampDetection>& lamps);
  // The robot was carried (lifted and put down, which the wheels do not see) to `pose`, in the
  // map frame: the next frame is a keyframe there, with no odometry from the one before and
  // nothing followed across the image from it; its lamps join landmarks as after a loop.
  void carried(const Pose2& pose);
  // Solves a last time, merges and drops landmarks, and gives the map's lamps and the drive.
  MappingResult finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::mapping
