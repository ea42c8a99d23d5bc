#pragma once
// Online calibration of the wheel odometry from the camera's heading measurements. Unequal
// wheel radii make dead reckoning turn when the robot drives straight (0.7 % between the wheels
// of a 0.4 m track is 1 degree per metre), and a wrong track width scales every turn. With the
// camera a second late, the estimate the robot drives on is a second of dead reckoning ahead of
// the last measurement, so this drift is most of its heading error. Pairs of accepted pose
// measurements at least `min_travel` apart give the heading change the wheels should have
// reported; a recursive least-squares fit with forgetting learns
//   dR_true = (1 + turn_scale) dR + yaw_drift_per_m dS
// and the localizer corrects each wheel increment with it before the EKF sees it.

#include <deque>
#include <utility>

#include "lampnav/core/time.hpp"

namespace lampnav::fusion {

struct OdometryCalibrationOptions {
  bool enabled = true;
  double semi_axis = 0.20;    // m (robot.json)
  double min_travel = 0.5;    // m of travel between the two measurements of a pair
  double min_turn = 0.3;      // rad; smaller turns do not inform turn_scale
  double max_travel = 6.0;    // m; older measurements are forgotten
  double forgetting = 0.995;  // per pair: old pairs fade (wheels wear, loads change)
  double prior_drift = 0.02;  // rad/m, sigma of the prior on yaw_drift_per_m (around 0)
  double prior_scale = 0.05;  // sigma of the prior on turn_scale (around 0)
  double max_drift = 0.05;    // rad/m (2.9 degrees per metre); the estimate is clamped
  double max_scale = 0.05;
  void validate() const;
};

class OdometryCalibration {
 public:
  explicit OdometryCalibration(const OdometryCalibrationOptions& options = {});
  // Raw wheel increments (m) read at `stamp` (before correction).
  void wheels(Stamp stamp, double d_left, double d_right);
  // The heading of an accepted pose measurement captured at `stamp`, with its variance.
  void heading(Stamp stamp, double yaw, double variance);
  // Corrected wheel increments: the same forward travel, the heading change corrected.
  std::pair<double, double> correct(double d_left, double d_right) const;
  // After a kidnap: the measurements before it are not comparable with those after it.
  void forget_measurements();

  double yaw_drift_per_m() const { return drift_; }
  double turn_scale() const { return scale_; }
  int pairs() const { return pairs_; }
  int outliers() const { return outliers_; }

 private:
  struct Odometry {
    Stamp stamp;
    double s, r;  // cumulative raw forward travel (m) and heading change (rad)
  };
  struct Heading {
    Stamp stamp;
    double yaw, variance, s, r;
  };
  bool odometry_at(Stamp t, double* s, double* r) const;

  OdometryCalibrationOptions o_;
  std::deque<Odometry> odo_;
  std::deque<Heading> headings_;
  double s_ = 0, r_ = 0;
  // Normal equations of the fit in (drift, scale): A theta = b.
  double a11_ = 0, a12_ = 0, a22_ = 0, b1_ = 0, b2_ = 0;
  double drift_ = 0, scale_ = 0;
  int pairs_ = 0, outliers_ = 0;
};

}  // namespace lampnav::fusion
