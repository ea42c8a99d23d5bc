#pragma once
// Poses hashed by position, to ask "is any of them within r metres and a radians of this one?"
// in constant time: the places an earlier image allowed, carried to the next one (the
// enumeration's prior and its bookkeeping, global_localizer.hpp and hypothesis_set.cpp).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::fusion::detail {

class PoseGrid {
 public:
  // `reach_m`: the largest radius near() will be asked for (the cell's side). `values`, if
  // given, one per pose, for least().
  PoseGrid(const std::vector<Pose2>& poses, double reach_m,
           const std::vector<double>* values = nullptr)
      : poses_(&poses), values_(values), cell_(std::max(reach_m, 0.05)) {
    cells_.reserve(poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k)
      cells_[key(cell_of(poses[k].x()), cell_of(poses[k].y()))].push_back(k);
  }

  // Whether a pose of the grid lies within r_m (at most the reach) and r_rad of p.
  bool near(const Pose2& p, double r_m, double r_rad) const {
    return least(p, r_m, r_rad) < std::numeric_limits<double>::infinity();
  }
  // The least value of the poses within r_m and r_rad of p (0 without values); infinity when
  // there is none.
  double least(const Pose2& p, double r_m, double r_rad) const {
    double best = std::numeric_limits<double>::infinity();
    const std::int64_t cx = cell_of(p.x()), cy = cell_of(p.y());
    for (std::int64_t i = cx - 1; i <= cx + 1; ++i)
      for (std::int64_t j = cy - 1; j <= cy + 1; ++j) {
        const auto it = cells_.find(key(i, j));
        if (it == cells_.end()) continue;
        for (const std::size_t k : it->second) {
          const Pose2& q = (*poses_)[k];
          if ((q.translation() - p.translation()).squaredNorm() <= r_m * r_m &&
              std::abs(wrap_angle(q.yaw() - p.yaw())) <= r_rad)
            best = std::min(best, values_ ? (*values_)[k] : 0.0);
        }
      }
    return best;
  }

 private:
  std::int64_t cell_of(double v) const { return std::int64_t(std::floor(v / cell_)); }
  static std::int64_t key(std::int64_t i, std::int64_t j) { return i * 2000003 + j; }

  const std::vector<Pose2>* poses_;
  const std::vector<double>* values_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

}  // namespace lampnav::fusion::detail
