#include "view_jumps.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "lampnav/fusion/ekf.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::mapping {

namespace {

using Eigen::Vector2d;
using vision::LampDetection;

bool well_inside(const LampDetection& d, const CameraDescription& cam, double margin) {
  const double mu = margin * cam.width, mv = margin * cam.height;
  return d.view == vision::LampView::full && d.centre_px.x() >= mu && d.centre_px.y() >= mv &&
         d.centre_px.x() <= cam.width - mu && d.centre_px.y() <= cam.height - mv;
}

// The ceiling camera's view of the robot's motion between two frames (conventions.md: a camera
// looking up, camera x and y along the robot's at zero mount angles). A ceiling point at height h
// above the camera, at c in the normalized plane, is seen after a turn t and a move T of the robot
// (in its frame before) at R(-t) c + (R(-t) (M - T) - M) / h, M the camera's place on the robot,
// both vectors turned into the camera frame by its mount's yaw. The height is not known, only
// that it is at least min_height_m: a lamp's next place lies on a segment, and it may be
// measured up to `gate` off it, plus half of what the turn moves it (while the robot turns on
// the spot, the office drives' lamp centres wander off the predicted arc by up to 0.04).
class ViewMotion {
 public:
  ViewMotion(const CameraDescription& cam, const ViewJumpOptions& o)
      : cam_(cam), model_(cam), o_(o), mount_(cam.mount.xyz.head<2>()), yaw_(cam.mount.rpy.z()) {
    for (const Vector2d& c :
         {at(0, 0), at(cam.width - 1, 0), at(0, cam.height - 1), at(cam.width - 1, cam.height - 1)})
      corner_ = std::max(corner_, c.norm());
  }

  // Between the frames the wheels moved the robot by `step` (x, y, yaw in its frame before).
  void set(const fusion::StateVector& step) {
    turn_ = step.z();
    shift_ = rotated(rotated(mount_ - step.head<2>(), -turn_) - mount_, -yaw_) / o_.min_height_m;
    reach_ = o_.gate + shift_.norm();
  }

  // Whether some lamp of `other` is where `d` could have gone (forward: `d` in the earlier frame)
  // or come from. Cut lamps are compared like whole ones: their centre is the visible part's, or
  // the completed shape's, and a lamp whose cut changes that much is taken as gone.
  bool has_counterpart(const LampDetection& d, const std::vector<LampDetection>& other,
                       bool forward) const {
    for (const LampDetection& e : other)
      if (forward ? follows(d, e) : follows(e, d)) return true;
    return false;
  }

  // Whether `d`, with no counterpart in the earlier frame, could not have entered the view since:
  // a whole lamp well inside, or any lamp reaching further in (from its box's far side to the
  // nearest image side, in the normalized plane) than the motion and the least a lamp shows when
  // first seen allow.
  bool could_not_have_entered(const LampDetection& d) const {
    if (well_inside(d, cam_, o_.margin)) return true;
    const double uc = 0.5 * (d.bbox[0] + d.bbox[2]), vc = 0.5 * (d.bbox[1] + d.bbox[3]);
    const double r = cam_.width - 1, b = cam_.height - 1;
    const double depth =
        std::min({(at(d.bbox[2], vc) - at(0, vc)).norm(), (at(d.bbox[0], vc) - at(r, vc)).norm(),
                  (at(uc, d.bbox[3]) - at(uc, 0)).norm(), (at(uc, d.bbox[1]) - at(uc, b)).norm()});
    return depth > reach_ + std::abs(turn_) * corner_ + o_.enter;
  }

 private:
  Vector2d at(double u, double v) const { return model_.normalized_of_pixel({u, v}); }
  static Vector2d rotated(const Vector2d& p, double a) { return Eigen::Rotation2Dd(a) * p; }
  // Whether `later` lies where `earlier` goes, within the gate. Between two views of a lamp cut
  // by the border, its centre (the visible part's, or the completed shape's) moves by up to half
  // the part one view shows and the other does not, which shows in their lengths and widths.
  bool follows(const LampDetection& earlier, const LampDetection& later) const {
    const Vector2d from = rotated(earlier.centre, -turn_);
    const double len2 = shift_.squaredNorm();
    const double k = len2 > 0 ? std::clamp((later.centre - from).dot(shift_) / len2, 0.0, 1.0) : 0;
    const bool cut = earlier.view != vision::LampView::full && later.view != vision::LampView::full;
    const double slack = cut ? 0.5 * (std::abs(earlier.length - later.length) +
                                      std::abs(earlier.width - later.width))
                             : 0.0;
    return (later.centre - from - k * shift_).norm() <=
           o_.gate + slack + 0.5 * std::abs(turn_) * (earlier.centre.norm() + 0.3);
  }

  const CameraDescription& cam_;
  vision::PinholeCamera model_;
  const ViewJumpOptions& o_;
  Vector2d mount_;
  double yaw_ = 0, corner_ = 0;
  double turn_ = 0, reach_ = 0;
  Vector2d shift_{0, 0};  // the segment's far end from its near end
};

}  // namespace

std::vector<std::size_t> view_jumps(const std::vector<ViewFrame>& frames,
                                    const CameraDescription& cam, double semi_axis,
                                    const ViewJumpOptions& o) {
  // The frames with lamps, in order.
  std::vector<std::size_t> lit;
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].lamps && !frames[i].lamps->empty()) lit.push_back(i);
  ViewMotion motion(cam, o);
  auto jumped = [&](std::size_t a, std::size_t b) {
    motion.set(fusion::predict_motion(fusion::StateVector::Zero(), frames[b].left - frames[a].left,
                                      frames[b].right - frames[a].right, semi_axis));
    const auto& before = *frames[a].lamps;
    const auto& after = *frames[b].lamps;
    for (const LampDetection& d : before)
      if (motion.has_counterpart(d, after, true)) return false;  // a lamp stayed in view
    for (const LampDetection& d : after)
      if (!motion.has_counterpart(d, before, false) && motion.could_not_have_entered(d))
        return true;  // and a lamp is where it could not have come from
    return false;
  };
  std::vector<std::size_t> out;
  for (std::size_t k = 1; k + 1 < lit.size(); ++k) {
    if (!jumped(lit[k - 1], lit[k])) continue;
    // The new view holds in the next frame with lamps: not one bad frame.
    if (!jumped(lit[k - 1], lit[k + 1])) continue;
    out.push_back(lit[k]);
  }
  return out;
}

}  // namespace lampnav::mapping
