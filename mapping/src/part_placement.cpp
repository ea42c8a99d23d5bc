#include "part_placement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "lampnav/mapping/rigid_fit.hpp"

namespace lampnav::mapping {

namespace {

using Eigen::Vector2d;

// Points on a grid of square cells, for the ones near a place.
class PointGrid {
 public:
  PointGrid(std::vector<Vector2d> points, double cell) : points_(std::move(points)), cell_(cell) {
    for (std::size_t i = 0; i < points_.size(); ++i)
      if (indexable(points_[i], 0))  // a lamp or pose a failed solve left at NaN is nowhere
        cells_[key(cell_of(points_[i].x()), cell_of(points_[i].y()))].push_back(i);
  }
  // Calls f(index, distance) for each point within r of p.
  template <class F>
  void near(const Vector2d& p, double r, F&& f) const {
    if (!p.allFinite()) return;
    // A reach wider than the points' cells (a lamp a failed solve put kilometres up is surely
    // seen from as far), or past what a cell's index holds: every point is tried instead of
    // every cell within it.
    const double across = 2 * r / cell_ + 2;
    if (!(across * across <= static_cast<double>(cells_.size())) || !indexable(p, r)) {
      for (std::size_t i = 0; i < points_.size(); ++i) {
        if (!points_[i].allFinite()) continue;
        const double d = (points_[i] - p).norm();
        if (d <= r) f(i, d);
      }
      return;
    }
    const long x0 = cell_of(p.x() - r), x1 = cell_of(p.x() + r);
    const long y0 = cell_of(p.y() - r), y1 = cell_of(p.y() + r);
    for (long x = x0; x <= x1; ++x) {
      for (long y = y0; y <= y1; ++y) {
        const auto it = cells_.find(key(x, y));
        if (it == cells_.end()) continue;
        for (const std::size_t i : it->second) {
          const double d = (points_[i] - p).norm();
          if (d <= r) f(i, d);
        }
      }
    }
  }
  bool any_within(const Vector2d& p, double r) const {
    bool found = false;
    near(p, r, [&](std::size_t, double) { found = true; });
    return found;
  }
  const Vector2d& operator[](std::size_t i) const { return points_[i]; }

 private:
  long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  // Whether the cells within r of p have indices the key holds (2^31 cells either way: a
  // million kilometres of half-metre cells).
  bool indexable(const Vector2d& p, double r) const {
    return p.allFinite() && (std::max(std::abs(p.x()), std::abs(p.y())) + r) / cell_ <
                                static_cast<double>(std::numeric_limits<std::int32_t>::max());
  }
  static std::uint64_t key(long x, long y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
  }
  std::vector<Vector2d> points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

std::vector<Vector2d> positions(const std::vector<MappedLamp>& lamps) {
  std::vector<Vector2d> out;
  for (const auto& l : lamps) out.push_back(l.xyz.head<2>());
  return out;
}

// Where a drive surely saw every lamp: its path, away from its ends.
std::vector<Vector2d> sure_path(const std::vector<KeyframePose>& keyframes, int end_keyframes) {
  std::vector<Vector2d> out;
  for (int k = end_keyframes; k + end_keyframes < static_cast<int>(keyframes.size()); ++k)
    out.push_back(keyframes[k].pose.translation());
  return out;
}

// One lamp of the part (its axis turned by the motion) and one of the map: one kind, one height,
// one axis.
bool alike(const MappedLamp& a, double turn, const MappedLamp& b, const PlacementOptions& o) {
  if (a.shape != b.shape) return false;
  if (std::abs(a.length - b.length) > 0.25 * std::max(a.length, b.length)) return false;
  if (std::abs(a.xyz.z() - b.xyz.z()) > o.height_tolerance_m) return false;
  if (a.shape != graph::LampShape::rectangle) return true;
  return std::abs(wrap_angle(2 * (a.yaw + turn - b.yaw))) / 2 <= o.axis_tolerance;
}

struct Score {
  int shared = 0;
  int contradictions = 0;
  std::vector<std::pair<Vector2d, Vector2d>> pairs;  // part lamp, map lamp
};

class Placer {
 public:
  Placer(const DrivePart& map, const DrivePart& part, const PlacementOptions& o)
      : o_(o),
        map_(*map.lamps),
        part_(*part.lamps),
        map_lamps_(positions(map_), 1.0),
        map_path_(sure_path(*map.keyframes, o.end_keyframes), 0.5),
        part_path_(sure_path(*part.keyframes, o.end_keyframes), 0.5) {}

  // How near a drive must have passed to surely have mapped a lamp at this height.
  double sure_within(double z) const {
    return std::max(o_.sure_m, o_.sure_per_height * (z - o_.camera_height_m));
  }

  // The part's lamps on the map's through T; with `whole`, also what contradicts T.
  Score score(const Pose2& T, bool whole, double match_m) const {
    Score s;
    std::vector<bool> matched(map_.size(), false);
    for (const auto& l : part_) {
      const Vector2d q = T.transform_from(l.xyz.head<2>());
      std::size_t nearest = map_.size();
      double nearest_d = o_.clash_m;
      map_lamps_.near(q, o_.clash_m, [&](std::size_t i, double d) {
        if (d < nearest_d) {
          nearest_d = d;
          nearest = i;
        }
      });
      if (nearest < map_.size() && nearest_d <= match_m && alike(l, T.yaw(), map_[nearest], o_)) {
        ++s.shared;
        matched[nearest] = true;
        s.pairs.emplace_back(l.xyz.head<2>(), map_[nearest].xyz.head<2>());
      } else if (nearest < map_.size() ||
                 (whole && map_path_.any_within(q, sure_within(l.xyz.z())))) {
        ++s.contradictions;  // beside a lamp, on one of another kind, or where the map saw none
      }
    }
    if (whole) {
      const Pose2 back = T.inverse();
      for (std::size_t i = 0; i < map_.size(); ++i)
        if (!matched[i] && part_path_.any_within(back.transform_from(map_[i].xyz.head<2>()),
                                                 sure_within(map_[i].xyz.z())))
          ++s.contradictions;  // the part passed under a lamp of the map and did not map it
    }
    return s;
  }

  // The motions that put at least min_shared lamps onto the map's, refined, distinct.
  std::vector<Pose2> candidates() const {
    std::vector<Pose2> out;
    Vector2d centre = Vector2d::Zero();
    for (const auto& l : part_) centre += l.xyz.head<2>();
    centre /= static_cast<double>(std::max<std::size_t>(1, part_.size()));
    auto known = [&](const Pose2& T) {
      for (const Pose2& c : out)
        if ((c.transform_from(centre) - T.transform_from(centre)).norm() < 0.3 &&
            std::abs(wrap_angle(c.yaw() - T.yaw())) < 0.05)
          return true;
      return false;
    };
    const PointGrid part_lamps(positions(part_), 1.0);
    for (std::size_t i = 0; i < part_.size(); ++i) {
      // The part lamp's nearest neighbours, at least a metre away.
      std::vector<std::pair<double, std::size_t>> near;
      part_lamps.near(part_[i].xyz.head<2>(), o_.max_pair_m, [&](std::size_t j, double d) {
        if (d >= 1.0) near.emplace_back(d, j);
      });
      std::sort(near.begin(), near.end());
      if (static_cast<int>(near.size()) > o_.neighbours) near.resize(o_.neighbours);
      const Vector2d pi = part_[i].xyz.head<2>();
      for (const auto& [d, j] : near) {
        const Vector2d pj = part_[j].xyz.head<2>();
        const double dir_p = std::atan2(pj.y() - pi.y(), pj.x() - pi.x());
        for (std::size_t a = 0; a < map_.size(); ++a) {
          if (part_[i].shape != map_[a].shape) continue;
          const Vector2d ma = map_[a].xyz.head<2>();
          map_lamps_.near(ma, d + o_.pair_tolerance_m, [&](std::size_t b, double dd) {
            if (b == a || std::abs(dd - d) > o_.pair_tolerance_m) return;
            const Vector2d mb = map_[b].xyz.head<2>();
            const double yaw = wrap_angle(std::atan2(mb.y() - ma.y(), mb.x() - ma.x()) - dir_p);
            if (!alike(part_[i], yaw, map_[a], o_) || !alike(part_[j], yaw, map_[b], o_)) return;
            const Pose2 T(ma - Pose2(0, 0, yaw).transform_from(pi), yaw);
            if (known(T)) return;
            Score s = score(T, false, o_.seek_m);
            if (s.shared < o_.min_shared) return;
            Pose2 refined = fit_rigid(s.pairs);
            s = score(refined, false, o_.match_m);
            if (s.shared < o_.min_shared) return;
            refined = fit_rigid(s.pairs);
            if (!known(refined)) out.push_back(refined);
          });
        }
      }
    }
    return out;
  }

 private:
  const PlacementOptions& o_;
  const std::vector<MappedLamp>& map_;
  const std::vector<MappedLamp>& part_;
  PointGrid map_lamps_, map_path_, part_path_;
};

}  // namespace

Placement place_part(const DrivePart& map, const DrivePart& part, const PlacementOptions& o) {
  Placement out;
  if (part.lamps->size() < static_cast<std::size_t>(o.min_shared) ||
      map.lamps->size() < static_cast<std::size_t>(o.min_shared))
    return out;
  const Placer placer(map, part, o);
  std::vector<PlacementFit> fitting;
  for (const Pose2& T : placer.candidates()) {
    const Score s = placer.score(T, true, o.match_m);
    if (s.shared < o.min_shared) continue;
    if (s.contradictions == 0)
      fitting.push_back({T, s.shared});
    else if (s.contradictions == 1)
      out.near_fits.push_back({T, s.shared});
  }
  out.fitting = static_cast<int>(fitting.size());
  std::stable_sort(fitting.begin(), fitting.end(),
                   [](const auto& a, const auto& b) { return a.shared > b.shared; });
  if (fitting.size() == 1) {
    out.motion = fitting.front().motion;
    out.shared = fitting.front().shared;
  }
  out.fits = std::move(fitting);
  return out;
}

}  // namespace lampnav::mapping
