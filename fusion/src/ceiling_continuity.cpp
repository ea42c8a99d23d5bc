#include "lampnav/fusion/ceiling_continuity.hpp"

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
}

namespace {

// One frame's lamps in the robot's base frame, each with the spread (m) a floor bump's tilt
// gives it (the lamp's height above the camera times 1 + |n|^2).
struct Sighting {
  Stamp stamp;
  std::vector<Eigen::Vector2d> lamps;
  std::vector<double> tilt_reach;
};

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

  Impl(const CameraDescription& camera, double lamp_height, const CeilingContinuityOptions& opt)
      : model(camera), geometry(camera), z(lamp_height), o(opt) {
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

  bool comparable(const Sighting& from, Stamp to, const OdometryTrack& odometry) const {
    return from.stamp < to && from.stamp >= odometry.first_stamp() &&
           odometry.travel(from.stamp, to) <= o.max_travel_m;
  }

  // `to`'s lamps against `from`'s, carried by the wheels.
  Agreement compare(const Sighting& from, const Sighting& to, const OdometryTrack& odometry) const {
    Agreement a;
    const Pose2 moved = odometry.at(to.stamp).between(odometry.at(from.stamp));
    const Pose2 back = moved.inverse();
    const double travelled = o.gate_per_m * odometry.travel(from.stamp, to.stamp);
    std::vector<Eigen::Vector2d> carried;
    for (const auto& p : from.lamps) carried.push_back(moved.transform_from(p));
    // Each frame has its own bump: the difference of two spreads.
    const auto gate = [&](double reach_a, double reach_b) {
      const double tilt = o.tilt_sigma * std::hypot(reach_a, reach_b);
      return o.gate_sigmas * std::hypot(tilt, o.sigma_m) + travelled;
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
};

CeilingContinuity::CeilingContinuity(const CameraDescription& camera, double lamp_height,
                                     const CeilingContinuityOptions& options)
    : impl_(std::make_unique<Impl>(camera, lamp_height, options)) {}
CeilingContinuity::~CeilingContinuity() = default;
CeilingContinuity::CeilingContinuity(CeilingContinuity&&) noexcept = default;

void CeilingContinuity::reset() {
  impl_->anchor.reset();
  impl_->odd.reset();
}

ContinuityVerdict CeilingContinuity::frame(Stamp stamp,
                                           const std::vector<vision::LampDetection>& lamps,
                                           const OdometryTrack& odometry) {
  Impl& m = *impl_;
  ContinuityVerdict v;
  Sighting now{stamp, {}, {}};
  const double above = m.z - m.geometry.mount_origin().z();
  for (const auto& l : lamps) {
    if (l.view == vision::LampView::partial) continue;
    if (const auto b = m.geometry.base_point(l.centre, m.z)) {
      now.lamps.push_back(*b);
      now.tilt_reach.push_back(above * (1 + l.centre.squaredNorm()));
    }
  }
  if (now.lamps.empty() || odometry.empty()) return v;
  if (m.anchor && stamp <= m.anchor->stamp) return v;  // out of order: neither compared nor kept
  // The frame becomes the one later frames are held against.
  const auto anchor_on = [&m](Sighting& s) {
    m.anchor = std::move(s);
    m.odd.reset();
  };
  if (!m.anchor || !m.comparable(*m.anchor, stamp, odometry)) {
    anchor_on(now);
    return v;
  }
  const Agreement a = m.compare(*m.anchor, now, odometry);
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
  if (m.odd && m.comparable(*m.odd, stamp, odometry) &&
      m.compare(*m.odd, now, odometry).matched > 0) {
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
