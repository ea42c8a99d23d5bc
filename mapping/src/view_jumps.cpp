#include "view_jumps.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "lampnav/vision/camera_models.hpp"

namespace lampnav::mapping {

namespace {

using Eigen::Vector2d;
using vision::LampDetection;

bool whole(const LampDetection& d) { return d.view == vision::LampView::full; }

bool well_inside(const LampDetection& d, const CameraDescription& cam, double margin) {
  const double mu = margin * cam.width, mv = margin * cam.height;
  return whole(d) && d.centre_px.x() >= mu && d.centre_px.y() >= mv &&
         d.centre_px.x() <= cam.width - mu && d.centre_px.y() <= cam.height - mv;
}

// A lamp of a frame with lamps as the rules see it: the detection, the lamp it is followed as
// (its track), and the range of its inverse height above the camera (1/m) that its views up to
// this frame allow (until they tell it, that of the heights told so far in the drive, widened).
struct Sighting {
  const LampDetection* d = nullptr;
  int track = -1;
  double w_lo = 0, w_hi = 0;
  double height = 0;  // m, 0: not yet told
};

// The ceiling camera's view of the robot's motion between two frames (conventions.md: a camera
// looking up, camera x and y along the robot's at zero mount angles). A ceiling point at height h
// above the camera, at c in the normalized plane, is seen after a turn t and a move T of the robot
// (in its frame before) at R(-t) c + (R(-t) (M - T) - M) / h, M the camera's place on the robot,
// both vectors turned into the camera frame by its mount's yaw. With 1 / h in a range, a lamp's
// next place lies on a segment, and it may be measured up to `gate` off it, plus half of what the
// turn moves it (while the robot turns on the spot, the office drives' lamp centres wander off the
// predicted arc by up to 0.04 with the height unknown), or a quarter once its height is told
// (such lamps were measured at most 0.042 off while turning, and 0.055 while not).
class ViewMotion {
 public:
  ViewMotion(const CameraDescription& cam, const ViewJumpOptions& o)
      : cam_(cam),
        model_(cam),
        o_(o),
        mount_(cam.mount.xyz.head<2>()),
        yaw_(cam.mount.rpy.z()),
        corner_(model_.corner_radius()) {}

  // Between the frames the wheels moved the robot by `step` (in its frame before).
  void set(const Pose2& step) {
    turn_ = step.yaw();
    move_ = rotated(rotated(mount_ - step.translation(), -turn_) - mount_, -yaw_);
    reach_ = o_.gate + move_.norm() / o_.min_height_m;
  }

  // Whether some lamp of `other` is where `s` could have gone (forward: `s` in the earlier frame)
  // or come from. Cut lamps are compared like whole ones: their centre is the visible part's, or
  // the completed shape's, and a lamp whose cut changes that much is taken as gone. With
  // `whole_in_one`, two views cut by the border are not taken as one lamp: the cut's slack lets
  // a look-alike lamp at the border pass.
  bool has_counterpart(const Sighting& s, const std::vector<Sighting>& other, bool forward,
                       bool whole_in_one = false) const {
    for (const Sighting& e : other) {
      if (whole_in_one && !whole(*s.d) && !whole(*e.d)) continue;
      if ((forward ? excess(s, *e.d) : excess(e, *s.d)) <= 0) return true;
    }
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

  // How much further `later` lies from where `earlier` goes than the gate allows (<= 0: within).
  // Between two views of a lamp cut by the border, its centre (the visible part's, or the
  // completed shape's) moves by up to half the part one view shows and the other does not, which
  // shows in their lengths and widths.
  double excess(const Sighting& earlier, const LampDetection& later) const {
    const LampDetection& e = *earlier.d;
    const Vector2d from = rotated(e.centre, -turn_) + earlier.w_lo * move_;
    const Vector2d shift = (earlier.w_hi - earlier.w_lo) * move_;
    const double len2 = shift.squaredNorm();
    const double k = len2 > 0 ? std::clamp((later.centre - from).dot(shift) / len2, 0.0, 1.0) : 0;
    const bool cut = !whole(e) && !whole(later);
    const double slack =
        cut ? 0.5 * (std::abs(e.length - later.length) + std::abs(e.width - later.width)) : 0.0;
    const double wander = earlier.height > 0 ? 0.25 : 0.5;
    return (later.centre - from - k * shift).norm() -
           (o_.gate + slack + wander * std::abs(turn_) * (e.centre.norm() + 0.3));
  }

 private:
  Vector2d at(double u, double v) const { return model_.normalized_of_pixel({u, v}); }
  static Vector2d rotated(const Vector2d& p, double a) { return Eigen::Rotation2Dd(a) * p; }

  const CameraDescription& cam_;
  vision::PinholeCamera model_;
  const ViewJumpOptions& o_;
  Vector2d mount_;
  double yaw_ = 0, corner_ = 0;
  double turn_ = 0, reach_ = 0;
  Vector2d move_{0, 0};  // a ceiling point's shift times its height
};

// A lamp's place on the ceiling from one whole view, by the wheels: p + R (M + h R_mount c) for
// the robot at p, R, the camera at M, and the lamp h above it; here as a + h b.
struct Place {
  std::size_t k = 0;  // the frame with lamps
  Vector2d a, b;
};

// A track's views so far, summed to fit its height: the place a + h b stays put, so h is the
// least-squares slope of a's spread against b's (a taken from the first view's, for precision).
struct HeightFit {
  int n = 0;
  Vector2d origin{0, 0}, sa{0, 0}, sb{0, 0};
  double sab = 0, sbb = 0;

  void add(const Vector2d& a, const Vector2d& b) {
    if (n == 0) origin = a;
    const Vector2d ra = a - origin;
    ++n;
    sa += ra;
    sb += b;
    sab += ra.dot(b);
    sbb += b.squaredNorm();
  }
  // The height and its spread (the places' noise over the views' spread), or a spread of
  // infinity while the views lie too close together to tell.
  std::pair<double, double> height(double place_noise, double parallax) const {
    if (n < 3) return {0, HUGE_VAL};
    const double den = sbb - sb.squaredNorm() / n;
    if (den < parallax * parallax) return {0, HUGE_VAL};
    const double h = -(sab - sa.dot(sb) / n) / den;
    return {h, place_noise * h / std::sqrt(den)};
  }
};

// The lamps of the frames with lamps (lit), each followed from the frame with lamps before it:
// it takes the track of the lamp it lies nearest to where the wheels take it, within twice the
// gate (a frame bumped off by more than the gate keeps its track), else a new one. Its inverse
// height's range comes from its track's whole views up to it. `places` gets each track's whole
// views.
std::vector<std::vector<Sighting>> follow_lamps(const std::vector<ViewFrame>& frames,
                                                const std::vector<std::size_t>& lit,
                                                const CameraDescription& cam,
                                                const ViewJumpOptions& o, ViewMotion& motion,
                                                std::vector<std::vector<Place>>& places,
                                                std::vector<double>* residuals) {
  std::vector<std::vector<Sighting>> out(lit.size());
  std::vector<HeightFit> fits;
  double lowest = HUGE_VAL, highest = 0;  // m, the heights told so far
  const Vector2d mount = cam.mount.xyz.head<2>();
  const Eigen::Rotation2Dd mount_yaw(cam.mount.rpy.z());
  for (std::size_t k = 0; k < lit.size(); ++k) {
    const auto& lamps = *frames[lit[k]].lamps;
    out[k].resize(lamps.size());
    if (k > 0) motion.set(frames[lit[k - 1]].wheels.between(frames[lit[k]].wheels));
    const Pose2& p = frames[lit[k]].wheels;
    const Eigen::Rotation2Dd turn(p.yaw());
    for (std::size_t j = 0; j < lamps.size(); ++j) {
      Sighting& s = out[k][j];
      s.d = &lamps[j];
      double best = o.gate;
      const Sighting* from = nullptr;
      if (k > 0)
        for (const Sighting& e : out[k - 1]) {
          const double x = motion.excess(e, lamps[j]);
          if (x <= best) {
            best = x;
            from = &e;
          }
        }
      if (from) s.track = from->track;
      if (residuals && from && from->height > 0 && whole(*from->d) && whole(lamps[j]))
        residuals->push_back(best + o.gate);
      if (s.track < 0) {
        s.track = static_cast<int>(fits.size());
        fits.emplace_back();
        places.emplace_back();
      }
      HeightFit& fit = fits[s.track];
      if (whole(lamps[j])) {
        const Place place{k, p.translation() + turn * mount, turn * (mount_yaw * lamps[j].centre)};
        fit.add(place.a, place.b);
        places[s.track].push_back(place);
      }
      const auto [h, spread] = fit.height(o.place_noise, o.parallax);
      if (spread < HUGE_VAL && h - 4 * spread > o.min_height_m) {
        s.height = h;
        s.w_lo = 1 / (h + 4 * spread);
        s.w_hi = 1 / (h - 4 * spread);
        lowest = std::min(lowest, h);
        highest = std::max(highest, h);
      } else {
        // A building's lamps hang at much the same height: a lamp not yet told is taken to be
        // between half the lowest and twice the highest told so far (at least min_height_m).
        s.w_lo = highest > 0 ? 1 / (o.told_spread * highest) : 0;
        s.w_hi =
            std::min(1 / o.min_height_m, lowest < HUGE_VAL ? o.told_spread / lowest : HUGE_VAL);
      }
    }
  }
  return out;
}

// Between frames with lamps a and b: the view of a gone from where the wheels' motion could
// have taken it, and a lamp of b where it could not have come from. The view is gone when no
// lamp whole in a or b stayed, and some lamp of a has no counterpart at all: a lamp cut by the
// border in both is no sign that the view stayed (the cut's slack lets a look-alike pass), unless
// every lamp of a is still there (a lamp that comes on beside lamps at the border).
bool jumped(const std::vector<Sighting>& before, const std::vector<Sighting>& after,
            const ViewMotion& motion) {
  bool all_stayed = true;
  for (const Sighting& s : before) {
    if (motion.has_counterpart(s, after, true, true)) return false;  // a lamp stayed in view
    all_stayed = all_stayed && motion.has_counterpart(s, after, true);
  }
  if (all_stayed) return false;
  for (const Sighting& s : after)
    if (!motion.has_counterpart(s, before, false) && motion.could_not_have_entered(*s.d))
      return true;  // and a lamp is where it could not have come from
  return false;
}

// Lamps followed across a boundary between frames with lamps whose places by the wheels move: a
// lamp does not move, so where every lamp followed across it moves by more than `moved` times its
// height, the robot was put down where the ceiling looks nearly alike, closer than the
// frame-to-frame gate can tell. The places of up to `window` whole views on each side are
// averaged, which takes out most of what floor bumps add to each view. Only lamps whose views
// before the boundary told their height speak: the move is the least over that height's range
// (a move along the drive looks much like a lamp a little higher or lower).
std::vector<std::size_t> moved_places(const std::vector<std::vector<Sighting>>& sightings,
                                      const std::vector<std::vector<Place>>& places,
                                      const ViewJumpOptions& o) {
  // The height range each track's views had told by each frame: looked up before a boundary.
  struct Told {
    std::size_t k;
    double lo, hi;
  };
  std::vector<std::vector<Told>> heights(places.size());
  for (std::size_t k = 0; k < sightings.size(); ++k)
    for (const Sighting& s : sightings[k])
      if (s.height > 0) heights[s.track].push_back({k, 1 / s.w_hi, 1 / s.w_lo});
  const auto span = static_cast<std::size_t>(2 * o.window);
  std::vector<double> least(sightings.size(), HUGE_VAL);
  for (std::size_t t = 0; t < places.size(); ++t) {
    const auto& p = places[t];
    if (p.size() < 6) continue;
    for (std::size_t i = 3; i + 3 <= p.size(); ++i) {
      const std::size_t k = p[i].k;  // the boundary: between the frames before k and k
      if (p[i - 1].k + 1 != k && p[i - 1].k + span < k) continue;
      const auto& ht = heights[t];
      const auto it = std::lower_bound(ht.begin(), ht.end(), k,
                                       [](const Told& x, std::size_t kk) { return x.k < kk; });
      if (it == ht.begin()) continue;  // its views before told no height
      const double lo = std::prev(it)->lo, hi = std::prev(it)->hi;
      Vector2d da(0, 0), db(0, 0);
      int nb = 0, na = 0;
      for (std::size_t j = i; j > 0 && nb < o.window && p[j - 1].k + span >= k; --j, ++nb) {
        da -= p[j - 1].a;
        db -= p[j - 1].b;
      }
      da /= std::max(nb, 1);
      db /= std::max(nb, 1);
      Vector2d ma(0, 0), mb(0, 0);
      for (std::size_t j = i; j < p.size() && na < o.window && p[j].k < k + span; ++j, ++na) {
        ma += p[j].a;
        mb += p[j].b;
      }
      if (nb < 3 || na < 3) continue;
      da += ma / na;
      db += mb / na;
      // The places' move, least over the heights the lamp may have.
      const double h =
          db.squaredNorm() > 0 ? std::clamp(-da.dot(db) / db.squaredNorm(), lo, hi) : lo;
      const double d = (da + h * db).norm() / h;
      // Every boundary this one spans: a lamp whose whole views skip frames speaks for each.
      for (std::size_t q = p[i - 1].k + 1; q <= k; ++q) least[q] = std::min(least[q], d);
    }
  }
  // The line: `moved`, or more on a bumpier floor, where the drive's own lamps wander further.
  // The floor's wander is measured away from the moves over `moved` (a carry's, and its
  // neighbours', which mix views of both sides).
  std::vector<char> near(least.size(), 0);
  for (std::size_t k = 0; k < least.size(); ++k)
    if (least[k] != HUGE_VAL && least[k] > o.moved)
      for (std::size_t q = k > span ? k - span : 0; q < std::min(least.size(), k + span + 1); ++q)
        near[q] = 1;
  std::vector<double> moves;
  for (std::size_t k = 0; k < least.size(); ++k)
    if (least[k] != HUGE_VAL && !near[k]) moves.push_back(least[k]);
  if (moves.empty()) moves.push_back(0);
  const auto p90 = moves.begin() + moves.size() * 9 / 10;
  std::nth_element(moves.begin(), p90, moves.end());
  const double line = std::max(o.moved, o.moved_over_p90 * *p90);
  // A jump is where `least` peaks above the line: its neighbours mix views of both sides.
  std::vector<std::size_t> out;
  for (std::size_t k = 1; k < least.size(); ++k) {
    if (least[k] == HUGE_VAL || least[k] <= line) continue;
    bool peak = true;
    for (std::size_t q = k > span ? k - span : 0; q < std::min(least.size(), k + span + 1); ++q)
      if (least[q] != HUGE_VAL && (least[q] > least[k] || (least[q] == least[k] && q < k)))
        peak = false;
    if (peak) out.push_back(k);
  }
  return out;
}

}  // namespace

std::vector<std::size_t> view_jumps(const std::vector<ViewFrame>& frames,
                                    const CameraDescription& cam, const ViewJumpOptions& o) {
  // The frames with lamps, in order.
  std::vector<std::size_t> lit;
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].lamps && !frames[i].lamps->empty()) lit.push_back(i);
  // The gate, wider on a bumpier floor: where the drive's whole lamps of known height lie off
  // their predicted places further than on the office's floor. Then the lamps are followed again
  // with it (`motion` reads the gate from `g`).
  ViewJumpOptions g = o;
  ViewMotion motion(cam, g);
  std::vector<std::vector<Place>> places;
  std::vector<double> off;
  std::vector<std::vector<Sighting>> seen = follow_lamps(frames, lit, cam, g, motion, places, &off);
  if (off.size() >= 100) {
    const auto p99 = off.begin() + off.size() * 99 / 100;
    std::nth_element(off.begin(), p99, off.end());
    g.gate = std::max(o.gate, o.gate_over_p99 * *p99);
  }
  if (g.gate > o.gate) {
    places.clear();
    seen = follow_lamps(frames, lit, cam, g, motion, places, nullptr);
  }
  std::vector<std::size_t> out;
  for (std::size_t k = 1; k + 1 < lit.size(); ++k) {
    motion.set(frames[lit[k - 1]].wheels.between(frames[lit[k]].wheels));
    if (!jumped(seen[k - 1], seen[k], motion)) continue;
    // The new view holds in the next frame with lamps: not one bad frame.
    motion.set(frames[lit[k - 1]].wheels.between(frames[lit[k + 1]].wheels));
    if (!jumped(seen[k - 1], seen[k + 1], motion)) continue;
    // And from the frame with lamps before: not one bad frame before it either.
    if (k >= 2) {
      motion.set(frames[lit[k - 2]].wheels.between(frames[lit[k]].wheels));
      if (!jumped(seen[k - 2], seen[k], motion)) continue;
      motion.set(frames[lit[k - 2]].wheels.between(frames[lit[k + 1]].wheels));
      if (!jumped(seen[k - 2], seen[k + 1], motion)) continue;
    }
    out.push_back(lit[k]);
  }
  // A lamp's place moving where the view jumped as well is the same jump, seen a frame or two
  // off (the views averaged on its sides mix the two).
  const std::size_t pairs = out.size();
  for (const std::size_t k : moved_places(seen, places, g)) {
    bool same = false;
    for (std::size_t q = 0; q < pairs; ++q) {
      const auto at =
          static_cast<std::size_t>(std::lower_bound(lit.begin(), lit.end(), out[q]) - lit.begin());
      same = same || (at > k ? at - k : k - at) <= static_cast<std::size_t>(2 * o.window);
    }
    if (!same) out.push_back(lit[k]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace lampnav::mapping
