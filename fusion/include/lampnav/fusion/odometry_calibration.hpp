#pragma once
// Online calibration of the wheel odometry from the camera's pose measurements. Unequal
// wheel radii make dead reckoning turn when the robot drives straight (0.7 % between the wheels
// of a 0.4 m track is 1 degree per metre), and a wrong track width scales every turn. With the
// camera a second late, the estimate the robot drives on is a second of dead reckoning ahead of
// the last measurement, so this drift is most of its heading error. Pairs of accepted pose
// measurements at least `min_travel` apart give the heading change the wheels should have
// reported; a recursive least-squares fit with forgetting learns
//   dR_true = (1 + turn_scale) dR + yaw_drift_per_m dS
// Wheels whose mean radius is off (worn or soft tyres, a wheel radius off in the odometry) read
// every metre a few per cent long or short. The estimate then runs ahead of or behind the robot by
// that fraction of the second of travel since the last frame, and the EKF keeps it there: 1.3 cm of
// bias per per cent on the office's routes. Pairs of accepted positions at least
// `min_scale_travel` apart give the length of the way the wheels should have reported, and a
// second fit learns
//   dS_true = (1 + travel_scale) dS
// The localizer corrects each wheel increment with both before the EKF sees it.

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
  // The wheels' travel (off: the forward travel is taken as the wheels give it): a pair of
  // positions at least this far apart by the wheels (m). A centimetre of position noise is then a
  // quarter of a per cent of it; 2 m apart, the fit's noise moved the default wheels' replays by
  // up to 0.17 cm (docs/localization.md, "The wheels' travel").
  bool learn_travel = true;
  double min_scale_travel = 4.0;
  // Pairs the fit must hold before its scale corrects the wheels: one pair's is a per cent of
  // noise, and where lamps are far apart (round lamps 4.5 m apart) pairs come a minute apart.
  int min_travel_pairs = 20;
  double prior_travel_scale = 0.05;  // sigma of the prior on travel_scale (around 0)
  double max_travel_scale = 0.1;     // the estimate is clamped
  void validate() const;
};

class OdometryCalibration {
 public:
  explicit OdometryCalibration(const OdometryCalibrationOptions& options = {});
  // Raw wheel increments (m) read at `stamp` (before correction).
  void wheels(Stamp stamp, double d_left, double d_right);
  // The heading of an accepted pose measurement captured at `stamp`, with its variance.
  void heading(Stamp stamp, double yaw, double variance);
  // The position (m) of an accepted pose measurement captured at `stamp`, with its covariance
  // (xx, xy, yy; m^2).
  void position(Stamp stamp, double x, double y, double var_xx, double var_xy, double var_yy);
  // Corrected wheel increments: the forward travel scaled, the heading change corrected.
  std::pair<double, double> correct(double d_left, double d_right) const;
  // After a kidnap: the measurements before it are not comparable with those after it.
  void forget_measurements();

  double yaw_drift_per_m() const { return drift_; }
  double turn_scale() const { return scale_; }
  // The scale applied (0 until the fit holds min_travel_pairs pairs).
  double travel_scale() const { return travel_pairs_ >= o_.min_travel_pairs ? travel_scale_ : 0.0; }
  int pairs() const { return pairs_; }
  int outliers() const { return outliers_; }
  int travel_pairs() const { return travel_pairs_; }
  int travel_outliers() const { return travel_outliers_; }

 private:
  struct Odometry {
    Stamp stamp;
    double s, r;  // cumulative raw forward travel (m) and heading change (rad)
    double x, y;  // dead reckoning of the raw travel along the corrected heading (m)
  };
  struct Heading {
    Stamp stamp;
    double yaw, variance, s, r;
  };
  struct Position {
    Stamp stamp;
    double x, y, xx, xy, yy;  // measured (m, m^2)
    Odometry odo;             // the wheels' at the same time
  };
  bool odometry_at(Stamp t, Odometry* at) const;
  void fit_travel(const Position& p, const Position& q);

  OdometryCalibrationOptions o_;
  std::deque<Odometry> odo_;
  std::deque<Heading> headings_;
  double s_ = 0, r_ = 0, x_ = 0, y_ = 0, heading_ = 0;
  std::deque<Position> positions_;
  // Normal equations of the fit in (drift, scale): A theta = b.
  double a11_ = 0, a12_ = 0, a22_ = 0, b1_ = 0, b2_ = 0;
  double drift_ = 0, scale_ = 0;
  // The travel's fit, a scalar: (a_travel_ + prior) travel_scale = b_travel_.
  double a_travel_ = 0, b_travel_ = 0, travel_scale_ = 0;
  int pairs_ = 0, outliers_ = 0, travel_pairs_ = 0, travel_outliers_ = 0;
};

}  // namespace lampnav::fusion
