#pragma once
// Poses in the map's grid index (graph::GridIndex), to ask "which of them lie within r metres
// and a radians of this one?": the places an earlier image allowed, carried to the next one
// (the enumeration's prior and its bookkeeping, global_localizer.hpp and hypothesis_set.cpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/grid_index.hpp"

namespace lampnav::fusion::detail {

class PoseGrid {
 public:
  // `reach_m`: about the largest radius asked for (the cells' side). `values`, if given, one
  // per pose, for least().
  PoseGrid(const std::vector<Pose2>& poses, double reach_m,
           const std::vector<double>* values = nullptr)
      : poses_(&poses), values_(values), index_(std::max(reach_m, 0.05)) {
    for (std::size_t k = 0; k < poses.size(); ++k)
      index_.insert({poses[k].translation(), poses[k].translation()}, k);
  }

  // Whether a pose of the grid lies within r_m and r_rad of p.
  bool near(const Pose2& p, double r_m, double r_rad) const {
    return least(p, r_m, r_rad) < std::numeric_limits<double>::infinity();
  }
  // The least value of the poses within r_m and r_rad of p (0 without values); infinity when
  // there is none.
  double least(const Pose2& p, double r_m, double r_rad) const {
    double best = std::numeric_limits<double>::infinity();
    const Eigen::Vector2d r(r_m, r_m);
    index_.query({p.translation() - r, p.translation() + r}, [&](std::size_t k) {
      const Pose2& q = (*poses_)[k];
      if ((q.translation() - p.translation()).squaredNorm() <= r_m * r_m &&
          std::abs(wrap_angle(q.yaw() - p.yaw())) <= r_rad)
        best = std::min(best, values_ ? (*values_)[k] : 0.0);
    });
    return best;
  }

 private:
  const std::vector<Pose2>* poses_;
  const std::vector<double>* values_;
  graph::GridIndex index_;
};

}  // namespace lampnav::fusion::detail
