#include "look_alikes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>

#include "map_geometry.hpp"

namespace lampnav::fusion::detail {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kPairTolerance = 0.15;  // m: two lamps as far apart as the anchor's pair
constexpr int kAnchors = 3;
constexpr std::size_t kCounted = 256;  // lamps a motion is counted on, at most
constexpr double kNear = 10.0;     // m: the anchor's neighbourhood, where a motion is fitted first
constexpr std::size_t kQuick = 8;  // the anchor's nearest lamps, a rough motion's first test

// A rigid motion applied to many points: its rotation's sine and cosine taken once.
struct Moved {
  explicit Moved(const Pose2& T)
      : yaw(T.yaw()), c(std::cos(yaw)), s(std::sin(yaw)), t(T.translation()) {}
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
    return t + Eigen::Vector2d(c * p.x() - s * p.y(), s * p.x() + c * p.y());
  }
  double yaw, c, s;
  Eigen::Vector2d t;
};

// The lamps of a map in cells of a flat grid over its extent: the many small searches of
// look_alike_motions without the map's general index (hashed cells, a callback a lamp).
class LampGrid {
 public:
  explicit LampGrid(const std::vector<const graph::Lamp*>& lamps) {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo;
    for (const graph::Lamp* l : lamps) {
      lo = lo.cwiseMin(l->xyz.head<2>());
      hi = hi.cwiseMax(l->xyz.head<2>());
    }
    lo_ = lo;
    const Eigen::Vector2d span = (hi - lo).cwiseMax(1.0);
    // About one lamp a cell, and never cells smaller than a metre.
    cell_ = std::max(1.0, std::sqrt(span.x() * span.y() / double(lamps.size())));
    nx_ = static_cast<int>(span.x() / cell_) + 1;
    ny_ = static_cast<int>(span.y() / cell_) + 1;
    start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    for (const graph::Lamp* l : lamps) ++start_[index_of(l->xyz.head<2>()) + 1];
    for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
    lamps_.resize(lamps.size());
    std::vector<int> next(start_.begin(), start_.end() - 1);
    for (const graph::Lamp* l : lamps) lamps_[next[index_of(l->xyz.head<2>())]++] = l;
  }

  // Each lamp whose centre lies within `r` of p.
  template <class Visit>
  void within(const Eigen::Vector2d& p, double r, Visit visit) const {
    const int x0 = std::max(0, cell(p.x() - r - lo_.x())),
              x1 = std::min(nx_ - 1, cell(p.x() + r - lo_.x()));
    const int y0 = std::max(0, cell(p.y() - r - lo_.y())),
              y1 = std::min(ny_ - 1, cell(p.y() + r - lo_.y()));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const std::size_t c = static_cast<std::size_t>(y) * nx_ + x;
        for (int k = start_[c]; k < start_[c + 1]; ++k)
          if ((lamps_[k]->xyz.head<2>() - p).squaredNorm() <= r * r) visit(*lamps_[k]);
      }
  }

  // Whether the rigid motion T carries `l` within 0.15 m of a lamp alike to it turned (as
  // map_geometry.hpp's lands_on_alike).
  bool lands_on_alike(const Moved& T, const graph::Lamp& l) const {
    bool found = false;
    within(T(l.xyz.head<2>()), 0.15,
           [&](const graph::Lamp& m) { found = found || alike_turned(m, l, T.yaw); });
    return found;
  }

  // The lamp alike to `l` nearest to p, within `r` (the lower id on a tie).
  const graph::Lamp* nearest_alike(const graph::Lamp& l, const Eigen::Vector2d& p, double r) const {
    const graph::Lamp* best = nullptr;
    double best_d = r;
    within(p, r, [&](const graph::Lamp& m) {
      const double d = (m.xyz.head<2>() - p).norm();
      if (alike(m, l) && (d < best_d || (d == best_d && best && m.id < best->id)))
        best_d = d, best = &m;
    });
    return best;
  }

 private:
  int cell(double offset) const {
    return static_cast<int>(std::floor(std::clamp(offset / cell_, -1.0, 1e6)));
  }
  std::size_t index_of(const Eigen::Vector2d& p) const {
    const int x = std::clamp(cell(p.x() - lo_.x()), 0, nx_ - 1);
    const int y = std::clamp(cell(p.y() - lo_.y()), 0, ny_ - 1);
    return static_cast<std::size_t>(y) * nx_ + x;
  }
  Eigen::Vector2d lo_;
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<int> start_;
  std::vector<const graph::Lamp*> lamps_;
};

// The rigid motion that carries the points `from` onto `to` best (least squares).
Pose2 fitted_motion(const std::vector<Eigen::Vector2d>& from,
                    const std::vector<Eigen::Vector2d>& to) {
  Eigen::Vector2d mf = Eigen::Vector2d::Zero(), mt = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < from.size(); ++k) mf += from[k], mt += to[k];
  mf /= double(from.size());
  mt /= double(to.size());
  double cross = 0, dot = 0;
  for (std::size_t k = 0; k < from.size(); ++k) {
    const Eigen::Vector2d p = from[k] - mf, q = to[k] - mt;
    cross += p.x() * q.y() - p.y() * q.x();
    dot += p.dot(q);
  }
  const double yaw = std::atan2(cross, dot);
  return Pose2(mt - Pose2(0, 0, yaw).transform_from(mf), yaw);
}

bool same_motion(const Pose2& a, const Pose2& b) {
  return (a.translation() - b.translation()).norm() < 0.3 &&
         std::abs(wrap_angle(a.yaw() - b.yaw())) < 3 * kDeg;
}

// Finds the look-alike motions of one map (look_alike_motions).
class Finder {
 public:
  Finder(const graph::TopologicalMap& map, double min_fraction)
      : map_(map), min_(min_fraction), lamps_(all_lamps(map)), grid_(lamps_) {
    const std::size_t every = std::max<std::size_t>(1, lamps_.size() / kCounted);
    for (std::size_t k = 0; k < lamps_.size() && counted_.size() < kCounted; k += every)
      counted_.push_back(lamps_[k]);
    misses_allowed_ = static_cast<std::size_t>(std::floor((1 - min_) * double(counted_.size())));
  }

  static std::vector<const graph::Lamp*> all_lamps(const graph::TopologicalMap& map) {
    std::vector<const graph::Lamp*> out;
    for (const auto& n : map.nodes())
      for (const auto& l : n.lamps) out.push_back(&l);
    return out;
  }

  std::vector<LookAlikeMotion> find() {
    if (lamps_.size() < 4) return {};
    for (int k = 0; k < kAnchors; ++k) from_anchor(*lamps_[lamps_.size() * k / kAnchors]);
    return std::move(found_);
  }

 private:
  // Every pair of lamps alike to the anchor and its nearest neighbour, as far apart, gives a
  // rough motion (the anchor onto the first, its neighbour onto the second).
  void from_anchor(const graph::Lamp& a) {
    const graph::Lamp* b = nullptr;
    double ab = std::numeric_limits<double>::infinity();
    for (const graph::Lamp* l : lamps_) {
      const double d = (l->xyz.head<2>() - a.xyz.head<2>()).norm();
      if (l != &a && d > 0.3 && d < ab) ab = d, b = l;
    }
    if (!b) return;
    anchor_ = a.xyz.head<2>();
    anchor_cells_.clear();
    for (std::size_t k = 0; k < found_.size(); ++k) index_at_anchor(k);
    near_ = map_.lamps_within(anchor_, kNear);  // nearest first
    quick_.assign(near_.begin(), near_.begin() + std::min(kQuick, near_.size()));
    const Eigen::Vector2d ab_v = b->xyz.head<2>() - anchor_;
    const double ab_angle = std::atan2(ab_v.y(), ab_v.x());
    for (const graph::Lamp* c : lamps_) {
      if (!alike(*c, a)) continue;
      const Eigen::Vector2d c_xy = c->xyz.head<2>();
      grid_.within(c_xy, ab + kPairTolerance, [&](const graph::Lamp& d) {
        const Eigen::Vector2d cd = d.xyz.head<2>() - c_xy;
        if (&d == c || !alike(d, *b) || std::abs(cd.norm() - ab) > kPairTolerance) return;
        const double yaw = wrap_angle(std::atan2(cd.y(), cd.x()) - ab_angle);
        consider(Pose2(c_xy - Pose2(0, 0, yaw).transform_from(anchor_), yaw));
      });
    }
  }

  void consider(const Pose2& rough) {
    // The identity, or a motion found already: it carries the anchor where that one does.
    const auto known = [&](const Pose2& T) {
      if (same_motion(T, Pose2())) return true;
      const Eigen::Vector2d at = T.transform_from(anchor_);
      const auto [cx, cy] = anchor_cell(at);
      for (long x = cx - 1; x <= cx + 1; ++x)
        for (long y = cy - 1; y <= cy + 1; ++y) {
          const auto it = anchor_cells_.find(cell_key(x, y));
          if (it == anchor_cells_.end()) continue;
          for (const std::size_t k : it->second)
            if ((found_[k].motion.transform_from(anchor_) - at).squaredNorm() < 0.09 &&
                std::abs(wrap_angle(found_[k].motion.yaw() - T.yaw())) < 3 * kDeg)
              return true;
        }
      return false;
    };
    if (known(rough) || !quick_test(rough)) return;
    const std::optional<Pose2> T = refined(rough);
    if (!T || known(*T)) return;
    const Moved moved(*T);
    std::size_t misses = 0;
    for (const graph::Lamp* l : counted_)
      if (!grid_.lands_on_alike(moved, *l) && ++misses > misses_allowed_) return;
    found_.push_back({*T, 1.0 - double(misses) / double(counted_.size())});
    index_at_anchor(found_.size() - 1);
  }

  // Most of the anchor's nearest lamps land within 0.5 m of lamps alike.
  bool quick_test(const Pose2& T) const {
    const Moved moved(T);
    std::size_t hits = 0;
    for (const graph::Lamp* l : quick_)
      if (grid_.nearest_alike(*l, moved(l->xyz.head<2>()), 0.5)) ++hits;
    return double(hits) >= min_ * double(quick_.size());
  }

  // A motion from one pair of lamps is off by the map's errors over their distance (a few cm
  // over 2 m turn it a degree, 0.7 m at 40 m): it is fitted again to the lamps it carries near
  // lamps alike, those near the anchor first, then the counted ones, each time nearer.
  std::optional<Pose2> refined(Pose2 T) {
    struct Pass {
      const std::vector<const graph::Lamp*>* lamps;
      double within;  // m
    };
    for (const Pass& pass :
         {Pass{&near_, 0.5}, Pass{&counted_, 0.5}, Pass{&counted_, 0.3}, Pass{&counted_, 0.15}}) {
      from_.clear();
      to_.clear();
      const Moved moved(T);
      for (const graph::Lamp* l : *pass.lamps) {
        const Eigen::Vector2d p = l->xyz.head<2>();
        if (const graph::Lamp* m = grid_.nearest_alike(*l, moved(p), pass.within)) {
          from_.push_back(p);
          to_.push_back(m->xyz.head<2>());
        }
      }
      if (double(from_.size()) < min_ * double(pass.lamps->size()) || from_.size() < 2)
        return std::nullopt;
      T = fitted_motion(from_, to_);
    }
    return T;
  }

  const graph::TopologicalMap& map_;
  double min_;
  std::vector<const graph::Lamp*> lamps_;
  LampGrid grid_;
  std::vector<const graph::Lamp*> counted_, near_, quick_;
  std::size_t misses_allowed_ = 0;
  Eigen::Vector2d anchor_ = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> from_, to_;
  std::vector<LookAlikeMotion> found_;
  // The found motions by the 1 m cell where each puts the anchor (known() in consider()).
  std::unordered_map<std::int64_t, std::vector<std::size_t>> anchor_cells_;
  static std::pair<long, long> anchor_cell(const Eigen::Vector2d& p) {
    return {std::lround(std::floor(p.x())), std::lround(std::floor(p.y()))};
  }
  // Shifted as unsigned: a negative cell's left shift is undefined (UBSan found it).
  static std::int64_t cell_key(long x, long y) {
    return static_cast<std::int64_t>((static_cast<std::uint64_t>(x) << 32) ^
                                     static_cast<std::uint32_t>(y));
  }
  void index_at_anchor(std::size_t k) {
    const auto [x, y] = anchor_cell(found_[k].motion.transform_from(anchor_));
    anchor_cells_[cell_key(x, y)].push_back(k);
  }
};

}  // namespace

std::vector<LookAlikeMotion> look_alike_motions(const graph::TopologicalMap& map,
                                                double min_fraction, int max_count) {
  if (max_count <= 0) return {};
  std::vector<LookAlikeMotion> found = Finder(map, min_fraction).find();
  std::sort(found.begin(), found.end(), [](const LookAlikeMotion& x, const LookAlikeMotion& y) {
    if (x.fraction != y.fraction) return x.fraction > y.fraction;
    return x.motion.translation().norm() < y.motion.translation().norm();
  });
  if (int(found.size()) > max_count) found.resize(max_count);
  return found;
}

}  // namespace lampnav::fusion::detail
