#include "lampnav/fusion/ceiling_continuity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

void CeilingContinuityOptions::validate() const {
  auto require = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"", "ceiling continuity options", field}, what);
  };
  require(tilt_sigma >= 0 && tilt_sigma < 0.5, "tilt_sigma", "must be an angle in [0, 0.5) rad");
  require(sigma_m > 0 && std::isfinite(sigma_m), "sigma_m", "must be a positive distance in m");
  require(gate_sigmas > 0 && std::isfinite(gate_sigmas), "gate_sigmas", "must be positive");
  require(gate_per_m >= 0 && std::isfinite(gate_per_m), "gate_per_m",
          "must be a non-negative fraction");
  require(max_travel_m > 0 && std::isfinite(max_travel_m), "max_travel_m",
          "must be a positive distance in m");
  require(margin >= 0 && margin < 0.5, "margin", "must be a fraction in [0, 0.5)");
  require(tilt_window >= 1 && tilt_window <= 100000, "tilt_window", "must be 1 to 100000 lamps");
  require(tilt_min_samples >= 1 && tilt_min_samples <= tilt_window, "tilt_min_samples",
          "must be 1 to tilt_window lamps");
  require(tilt_margin >= 1 && std::isfinite(tilt_margin), "tilt_margin",
          "must be a factor of at least 1");
  require(tilt_pair_travel_m > 0 && std::isfinite(tilt_pair_travel_m), "tilt_pair_travel_m",
          "must be a positive distance in m");
  require(tilt_match_m > 0 && std::isfinite(tilt_match_m), "tilt_match_m",
          "must be a positive distance in m");
  require(max_tilt_sigma >= tilt_sigma && max_tilt_sigma < 0.5, "max_tilt_sigma",
          "must be an angle from tilt_sigma to 0.5 rad");
}

namespace {

// One frame's lamps in the robot's base frame, each with the spread (m) a floor bump's tilt
// gives it (the lamp's height above the camera times 1 + |n|^2), and how a tilt of the camera
// moves it there (m a radian about the camera's x and y axes).
struct Sighting {
  Stamp stamp;
  std::vector<Eigen::Vector2d> lamps;
  std::vector<double> tilt_reach;
  std::vector<Eigen::Matrix2d> tilt_move;
};

// The median of a chi-square of two degrees of freedom (2 ln 2).
constexpr double kChi2Median2 = 1.3862943611198906;

struct Agreement {
  int matched = 0, appeared = 0, vanished = 0;
  // Neither frame explains the other: a lamp each where the other has none, none alike.
  bool odd() const { return matched == 0 && appeared > 0 && vanished > 0; }
};

}  // namespace

struct CeilingContinuity::Impl {
  vision::PinholeCamera model;
  CeilingGeometry geometry;
  double z;
  CeilingContinuityOptions o;
  std::optional<Sighting> anchor;  // the last frame that agreed with the ones before it
  std::optional<Sighting> odd;     // a frame after it that did not agree with it
  std::optional<Sighting> last;    // the last frame with lamps (the swing's pairs)
  // The swing: each matched lamp's offset squared in units of its spread for one radian of tilt
  // (the last tilt_window of them, a ring), and the tilt spread the gates use.
  std::vector<double> swing;
  std::size_t next_swing = 0;
  std::optional<double> learnt;
  double tilt;

  Impl(const CameraDescription& camera, double lamp_height, const CeilingContinuityOptions& opt)
      : model(camera), geometry(camera), z(lamp_height), o(opt), tilt(opt.tilt_sigma) {
    o.validate();
    if (!(std::isfinite(z) && z > geometry.mount_origin().z()))
      throw InputError({"", "ceiling continuity", "lamp_height"},
                       "must be above the ceiling camera");
  }

  // Whether a lamp at base point b (at the lamps' height) has its centre well inside the image.
  bool in_view(const Eigen::Vector2d& b) const {
    const auto n = geometry.predict(Pose2::identity(), Eigen::Vector3d(b.x(), b.y(), z));
    if (!n) return false;
    const Eigen::Vector2d px = model.pixel_of_normalized(*n);
    const double mu = o.margin * model.width(), mv = o.margin * model.height();
    return px.x() >= mu && px.x() <= model.width() - 1 - mu && px.y() >= mv &&
           px.y() <= model.height() - 1 - mv;
  }

  bool comparable(const Sighting& from, Stamp to, const OdometryTrack& odometry,
                  double max_travel) const {
    return from.stamp < to && from.stamp >= odometry.first_stamp() &&
           odometry.travel(from.stamp, to) <= max_travel;
  }

  // `to`'s lamps against `from`'s, carried by the wheels, with the tilt spread `tilt_sigma`.
  Agreement compare(const Sighting& from, const Sighting& to, const OdometryTrack& odometry,
                    double tilt_sigma) const {
    Agreement a;
    const Pose2 moved = odometry.at(to.stamp).between(odometry.at(from.stamp));
    const Pose2 back = moved.inverse();
    const double travelled = o.gate_per_m * odometry.travel(from.stamp, to.stamp);
    std::vector<Eigen::Vector2d> carried;
    for (const auto& p : from.lamps) carried.push_back(moved.transform_from(p));
    // Each frame has its own bump: the difference of two spreads.
    const auto gate = [&](double reach_a, double reach_b) {
      const double spread = tilt_sigma * std::hypot(reach_a, reach_b);
      return o.gate_sigmas * std::hypot(spread, o.sigma_m) + travelled;
    };
    const auto near = [&](const Eigen::Vector2d& p, double reach,
                          const std::vector<Eigen::Vector2d>& others,
                          const std::vector<double>& reaches) {
      for (std::size_t k = 0; k < others.size(); ++k)
        if ((others[k] - p).norm() <= gate(reach, reaches[k])) return true;
      return false;
    };
    for (std::size_t k = 0; k < to.lamps.size(); ++k) {
      if (near(to.lamps[k], to.tilt_reach[k], carried, from.tilt_reach))
        ++a.matched;
      else if (in_view(back.transform_from(to.lamps[k])))
        ++a.appeared;
    }
    for (std::size_t k = 0; k < carried.size(); ++k)
      if (!near(carried[k], from.tilt_reach[k], to.lamps, to.tilt_reach) && in_view(carried[k]))
        ++a.vanished;
    return a;
  }

  // The lamps of `to` each matched to the one lamp of `from` the wheels carried near it: their
  // offsets, in units of the spread a radian of tilt in each frame gives (tilt_move), are the
  // swing's samples.
  void learn_swing(const Sighting& from, const Sighting& to, const OdometryTrack& odometry) {
    const Pose2 moved = odometry.at(to.stamp).between(odometry.at(from.stamp));
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(moved.yaw()).toRotationMatrix();
    std::vector<Eigen::Vector2d> carried;
    for (const auto& p : from.lamps) carried.push_back(moved.transform_from(p));
    int added = 0;
    for (std::size_t k = 0; k < to.lamps.size(); ++k) {
      int near = 0;
      std::size_t match = 0;
      for (std::size_t i = 0; i < carried.size(); ++i)
        if ((carried[i] - to.lamps[k]).norm() <= o.tilt_match_m) {
          ++near;
          match = i;
        }
      if (near != 1) continue;
      const Eigen::Vector2d r = to.lamps[k] - carried[match];
      const Eigen::Matrix2d A = R * from.tilt_move[match];
      const Eigen::Matrix2d C = A * A.transpose() + to.tilt_move[k] * to.tilt_move[k].transpose();
      if (!(std::abs(C.determinant()) > 1e-12)) continue;
      const double d2 = r.dot(C.ldlt().solve(r));
      if (!std::isfinite(d2)) continue;
      ++added;
      if (swing.size() < static_cast<std::size_t>(o.tilt_window)) {
        swing.push_back(d2);
      } else {
        swing[next_swing] = d2;
        next_swing = (next_swing + 1) % swing.size();
      }
    }
    // No new sample (a frame with no lamp matched alone): the spread is as it was.
    if (added == 0 || swing.size() < static_cast<std::size_t>(o.tilt_min_samples)) return;
    std::vector<double> sorted = swing;
    auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    learnt = std::sqrt(*mid / kChi2Median2);
    // Taken once it is past the margin by twice its own standard error: the median of n
    // chi-squares of 2 degrees of freedom errs by 2 / sqrt(n) (of its 2 ln 2), the spread by half
    // that in proportion.
    const double n = static_cast<double>(swing.size());
    const double lower = *learnt * (1 - 1 / (std::log(2.0) * std::sqrt(n)));
    tilt =
        lower > o.tilt_margin * o.tilt_sigma ? std::min(*learnt, o.max_tilt_sigma) : o.tilt_sigma;
  }
};

CeilingContinuity::CeilingContinuity(const CameraDescription& camera, double lamp_height,
                                     const CeilingContinuityOptions& options)
    : impl_(std::make_unique<Impl>(camera, lamp_height, options)) {}
CeilingContinuity::~CeilingContinuity() = default;
CeilingContinuity::CeilingContinuity(CeilingContinuity&&) noexcept = default;

void CeilingContinuity::reset() {
  impl_->anchor.reset();
  impl_->odd.reset();
  impl_->last.reset();
}

double CeilingContinuity::tilt_sigma() const { return impl_->tilt; }
std::optional<double> CeilingContinuity::learnt_tilt_sigma() const { return impl_->learnt; }
int CeilingContinuity::tilt_samples() const { return static_cast<int>(impl_->swing.size()); }

ContinuityVerdict CeilingContinuity::frame(Stamp stamp,
                                           const std::vector<vision::LampDetection>& lamps,
                                           const OdometryTrack& odometry, bool steady) {
  Impl& m = *impl_;
  ContinuityVerdict v;
  Sighting now{stamp, {}, {}, {}};
  const double above = m.z - m.geometry.mount_origin().z();
  for (const auto& l : lamps) {
    if (l.view == vision::LampView::partial) continue;
    Eigen::Matrix2d d_n;
    if (const auto b = m.geometry.base_point(l.centre, m.z, &d_n)) {
      now.lamps.push_back(*b);
      now.tilt_reach.push_back(above * (1 + l.centre.squaredNorm()));
      now.tilt_move.push_back(d_n * CeilingGeometry::tilt_jacobian(l.centre));
    }
  }
  if (now.lamps.empty() || odometry.empty()) return v;
  if (m.anchor && stamp <= m.anchor->stamp) return v;  // out of order: neither compared nor kept
  if (m.o.learn_tilt) {
    if (m.last && m.comparable(*m.last, stamp, odometry, m.o.tilt_pair_travel_m))
      m.learn_swing(*m.last, now, odometry);
    m.last = now;
  }
  // The frame becomes the one later frames are held against.
  const auto anchor_on = [&m](Sighting& s) {
    m.anchor = std::move(s);
    m.odd.reset();
  };
  if (!m.anchor || !m.comparable(*m.anchor, stamp, odometry, m.o.max_travel_m)) {
    anchor_on(now);
    return v;
  }
  // While the robot is looked for (`steady`), the configured spread: see the header.
  const double gate_tilt = steady ? m.o.tilt_sigma : m.tilt;
  const Agreement a = m.compare(*m.anchor, now, odometry, gate_tilt);
  v.compared = true;
  v.since = m.anchor->stamp;
  v.matched = a.matched;
  v.appeared = a.appeared;
  v.vanished = a.vanished;
  if (!a.odd()) {
    anchor_on(now);
    return v;
  }
  v.odd = true;
  if (m.odd && m.comparable(*m.odd, stamp, odometry, m.o.max_travel_m) &&
      m.compare(*m.odd, now, odometry, gate_tilt).matched > 0) {
    v.broken = true;
    v.moved_by = m.odd->stamp;
    char why[240];
    std::snprintf(why, sizeof why,
                  "the ceiling camera saw a move the wheels did not: %d lamp%s in view %.2f s "
                  "before gone, %d where the wheels put none, in two frames that agree",
                  v.vanished, v.vanished > 1 ? "s" : "", to_seconds(stamp - m.anchor->stamp),
                  v.appeared);
    v.why = why;
    anchor_on(now);
    return v;
  }
  m.odd = std::move(now);
  return v;
}

}  // namespace lampnav::fusion
