#include "lampnav/fusion/odometry_calibration.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/core/pose2.hpp"

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
}

OdometryCalibration::OdometryCalibration(const OdometryCalibrationOptions& options) : o_(options) {
  o_.validate();
}

void OdometryCalibration::wheels(Stamp t, double dl, double dr) {
  s_ += (dl + dr) / 2;
  r_ += (dr - dl) / (2 * o_.semi_axis);
  odo_.push_back({t, s_, r_});
  // Keep the odometry of the last max_travel metres (and at least 3 s for late frames).
  while (odo_.size() > 2 && s_ - odo_[1].s > o_.max_travel &&
         t - odo_[1].stamp > std::chrono::seconds(3))
    odo_.pop_front();
}

bool OdometryCalibration::odometry_at(Stamp t, double* s, double* r) const {
  if (odo_.empty() || t < odo_.front().stamp || t > odo_.back().stamp) return false;
  auto it = std::lower_bound(odo_.begin(), odo_.end(), t,
                             [](const Odometry& o, Stamp x) { return o.stamp < x; });
  if (it->stamp == t || it == odo_.begin()) {
    *s = it->s;
    *r = it->r;
    return true;
  }
  const Odometry& a = *std::prev(it);
  const double f = to_seconds(t - a.stamp) / to_seconds(it->stamp - a.stamp);
  *s = a.s + f * (it->s - a.s);
  *r = a.r + f * (it->r - a.r);
  return true;
}

void OdometryCalibration::heading(Stamp t, double yaw, double variance) {
  if (!o_.enabled || !std::isfinite(yaw) || !(variance > 0)) return;
  Heading h{t, yaw, variance, 0, 0};
  if (!odometry_at(t, &h.s, &h.r)) return;
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

std::pair<double, double> OdometryCalibration::correct(double dl, double dr) const {
  if (!o_.enabled) return {dl, dr};
  const double ds = (dl + dr) / 2, dth = (dr - dl) / (2 * o_.semi_axis);
  const double corrected = (dth + drift_ * ds) / (1 - scale_);
  return {ds - o_.semi_axis * corrected, ds + o_.semi_axis * corrected};
}

void OdometryCalibration::forget_measurements() { headings_.clear(); }

}  // namespace lampnav::fusion
