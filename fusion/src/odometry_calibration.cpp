#include "lampnav/fusion/odometry_calibration.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/fusion/ekf.hpp"

namespace lampnav::fusion {

void OdometryCalibrationOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "odometry calibration options", field}, msg);
  };
  if (!(semi_axis > 0)) fail("semi_axis", "must be positive");
  if (!(min_travel > 0 && max_travel > min_travel))
    fail("min_travel", "must be positive and below max_travel");
  if (!(forgetting > 0.5 && forgetting <= 1)) fail("forgetting", "must be 0.5 to 1");
  if (!(prior_drift > 0 && prior_scale > 0)) fail("prior_drift", "priors must be positive");
  if (!(max_drift > 0 && max_scale > 0)) fail("max_drift", "limits must be positive");
  if (!(min_scale_travel > 0 && min_scale_travel < max_travel))
    fail("min_scale_travel", "must be positive and below max_travel");
  if (!(prior_travel_scale > 0)) fail("prior_travel_scale", "must be positive");
  if (min_travel_pairs < 0) fail("min_travel_pairs", "must not be negative");
  if (!(max_travel_scale > 0 && max_travel_scale < 0.5))
    fail("max_travel_scale", "must be above 0 and below 0.5");
}

OdometryCalibration::OdometryCalibration(const OdometryCalibrationOptions& options) : o_(options) {
  o_.validate();
}

void OdometryCalibration::wheels(Stamp t, double dl, double dr) {
  const double ds = (dl + dr) / 2, dth = (dr - dl) / (2 * o_.semi_axis);
  // The way is dead-reckoned (the EKF's motion model) with the raw travel along the heading as
  // corrected so far, so that the wheels' own turn does not bend it: its length between two
  // positions is then the raw travel's.
  const double turn = (dth + drift_ * ds) / (1 - scale_), a = o_.semi_axis;
  const StateVector way =
      predict_motion(StateVector(x_, y_, heading_), ds - a * turn, ds + a * turn, a);
  x_ = way.x();
  y_ = way.y();
  heading_ = way.z();
  s_ += ds;
  r_ += dth;
  odo_.push_back({t, s_, r_, x_, y_});
  // Keep the odometry of the last max_travel metres (and at least 3 s for late frames).
  while (odo_.size() > 2 && s_ - odo_[1].s > o_.max_travel &&
         t - odo_[1].stamp > std::chrono::seconds(3))
    odo_.pop_front();
}

bool OdometryCalibration::odometry_at(Stamp t, Odometry* at) const {
  if (odo_.empty() || t < odo_.front().stamp || t > odo_.back().stamp) return false;
  auto it = std::lower_bound(odo_.begin(), odo_.end(), t,
                             [](const Odometry& o, Stamp x) { return o.stamp < x; });
  if (it->stamp == t || it == odo_.begin()) {
    *at = *it;
    return true;
  }
  const Odometry& a = *std::prev(it);
  const double f = to_seconds(t - a.stamp) / to_seconds(it->stamp - a.stamp);
  auto mix = [f](double u, double v) { return u + f * (v - u); };
  *at = {t, mix(a.s, it->s), mix(a.r, it->r), mix(a.x, it->x), mix(a.y, it->y)};
  return true;
}

void OdometryCalibration::heading(Stamp t, double yaw, double variance) {
  if (!o_.enabled || !std::isfinite(yaw) || !(variance > 0)) return;
  Odometry at;
  if (!odometry_at(t, &at)) return;
  Heading h{t, yaw, variance, at.s, at.r};
  // Pair with the latest earlier measurement at least min_travel behind.
  const Heading* partner = nullptr;
  for (auto it = headings_.rbegin(); it != headings_.rend(); ++it) {
    if (it->stamp < t && h.s - it->s >= o_.min_travel) {
      partner = &*it;
      break;
    }
  }
  if (partner) {
    // The turn is the measured one (precise; zero on a straight run, where the scale is left to
    // its prior instead of being confused with the drift).
    const double ds = h.s - partner->s, turn = wrap_angle(h.yaw - partner->yaw);
    const double residual = wrap_angle(turn - (h.r - partner->r));
    // Only a real turn says anything about the scale; on straight runs it stays at its prior.
    const double dr = std::fabs(turn) > o_.min_turn ? turn : 0.0;
    // A residual far beyond what the current fit and the noise explain is a bad measurement
    // (or a slip): it does not enter the fit.
    const double predicted = drift_ * ds + scale_ * dr;
    const double sigma = std::sqrt(h.variance + partner->variance);
    if (pairs_ >= 10 && std::fabs(residual - predicted) > 4 * sigma + 0.02 * ds + 0.02) {
      ++outliers_;
      headings_.push_back(h);
      return;
    }
    const double w = 1.0 / (h.variance + partner->variance);
    const double l = o_.forgetting;
    a11_ = l * a11_ + w * ds * ds;
    a12_ = l * a12_ + w * ds * dr;
    a22_ = l * a22_ + w * dr * dr;
    b1_ = l * b1_ + w * ds * residual;
    b2_ = l * b2_ + w * dr * residual;
    ++pairs_;
    const double p1 = 1 / (o_.prior_drift * o_.prior_drift),
                 p2 = 1 / (o_.prior_scale * o_.prior_scale);
    const double m11 = a11_ + p1, m22 = a22_ + p2, det = m11 * m22 - a12_ * a12_;
    if (det > 0) {
      drift_ = std::clamp((m22 * b1_ - a12_ * b2_) / det, -o_.max_drift, o_.max_drift);
      scale_ = std::clamp((m11 * b2_ - a12_ * b1_) / det, -o_.max_scale, o_.max_scale);
    }
  }
  headings_.push_back(h);
  while (!headings_.empty() && h.s - headings_.front().s > o_.max_travel) headings_.pop_front();
}

void OdometryCalibration::position(Stamp t, double x, double y, double xx, double xy, double yy) {
  if (!o_.enabled || !o_.learn_travel || !std::isfinite(x) || !std::isfinite(y) || !(xx > 0) ||
      !(yy > 0) || !(xx * yy - xy * xy > 0))
    return;
  Position p{t, x, y, xx, xy, yy, {}};
  if (!odometry_at(t, &p.odo)) return;
  // Pair with the latest earlier position at least min_scale_travel behind by the wheels.
  const Position* q = nullptr;
  for (auto it = positions_.rbegin(); it != positions_.rend(); ++it) {
    if (it->stamp < t && p.odo.s - it->odo.s >= o_.min_scale_travel) {
      q = &*it;
      break;
    }
  }
  if (q) fit_travel(p, *q);
  positions_.push_back(p);
  while (!positions_.empty() && p.odo.s - positions_.front().odo.s > o_.max_travel)
    positions_.pop_front();
}

// One pair of positions in the fit of the travel's scale.
void OdometryCalibration::fit_travel(const Position& p, const Position& q) {
  // Lengths, which do not depend on how the wheels' frame is turned against the map's. A way
  // that doubles back says little of the travel: half of it at least must be in a line.
  const double length = std::hypot(p.odo.x - q.odo.x, p.odo.y - q.odo.y);
  const double mx = p.x - q.x, my = p.y - q.y, measured = std::hypot(mx, my);
  if (length < o_.min_scale_travel / 2 || !(measured > 0)) return;
  // The measured way's noise across it changes its length only to second order.
  const double ux = mx / measured, uy = my / measured;
  const double variance =
      ux * ux * (p.xx + q.xx) + 2 * ux * uy * (p.xy + q.xy) + uy * uy * (p.yy + q.yy);
  const double residual = measured - length;
  // As for headings: a residual far beyond what the fit and the noise explain (a slip, a wrong
  // measurement) does not enter the fit.
  if (travel_pairs_ >= 10 && std::fabs(residual - travel_scale_ * length) >
                                 4 * std::sqrt(variance) + 0.01 * length + 0.02) {
    ++travel_outliers_;
    return;
  }
  const double w = 1.0 / variance, l = o_.forgetting;
  a_travel_ = l * a_travel_ + w * length * length;
  b_travel_ = l * b_travel_ + w * length * residual;
  ++travel_pairs_;
  const double prior = 1 / (o_.prior_travel_scale * o_.prior_travel_scale);
  travel_scale_ =
      std::clamp(b_travel_ / (a_travel_ + prior), -o_.max_travel_scale, o_.max_travel_scale);
}

std::pair<double, double> OdometryCalibration::correct(double dl, double dr) const {
  if (!o_.enabled) return {dl, dr};
  const double ds = (dl + dr) / 2, dth = (dr - dl) / (2 * o_.semi_axis);
  const double corrected = (dth + drift_ * ds) / (1 - scale_);
  const double travel = (1 + travel_scale()) * ds;
  return {travel - o_.semi_axis * corrected, travel + o_.semi_axis * corrected};
}

void OdometryCalibration::forget_measurements() {
  headings_.clear();
  positions_.clear();
}

}  // namespace lampnav::fusion
