#pragma once
// Poses in a flat grid of cells (flat_grid.hpp), to ask "which of them lie within r metres and a
// radians of this one?": the places an earlier image allowed, carried to the next one (the
// enumeration's prior and its bookkeeping, global_localizer.hpp and hypothesis_set.cpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "flat_grid.hpp"
#include "lampnav/core/pose2.hpp"

namespace lampnav::fusion::detail {

class PoseGrid {
 public:
  // `reach_m`: about the largest radius asked for (the cells' side). `values`, if given, one
  // per pose, for least(). A 1,000-node building's places take 40,000 to 90,000 cells of a
  // gate; at most 131,072 (0.5 MB), or 16 a pose, larger cells past that.
  PoseGrid(const std::vector<Pose2>& poses, double reach_m,
           const std::vector<double>* values = nullptr)
      : poses_(&poses),
        values_(values),
        grid_(positions(poses), std::max(reach_m, 0.05),
              std::max(double(1 << 17), 16.0 * static_cast<double>(poses.size()))) {}

  // Whether a pose of the grid lies within r_m and r_rad of p.
  bool near(const Pose2& p, double r_m, double r_rad) const {
    return least(p, r_m, r_rad) < std::numeric_limits<double>::infinity();
  }
  // The least value of the poses within r_m and r_rad of p (0 without values); infinity when
  // there is none.
  double least(const Pose2& p, double r_m, double r_rad) const {
    double best = std::numeric_limits<double>::infinity();
    grid_.visit(p.translation(), r_m, [&](int k) {
      const Pose2& q = (*poses_)[k];
      if ((q.translation() - p.translation()).squaredNorm() <= r_m * r_m &&
          std::abs(wrap_angle(q.yaw() - p.yaw())) <= r_rad)
        best = std::min(best, values_ ? (*values_)[k] : 0.0);
    });
    return best;
  }

 private:
  static std::vector<Eigen::Vector2d> positions(const std::vector<Pose2>& poses) {
    std::vector<Eigen::Vector2d> out;
    out.reserve(poses.size());
    for (const Pose2& p : poses) out.push_back(p.translation());
    return out;
  }
  const std::vector<Pose2>* poses_;
  const std::vector<double>* values_;
  FlatGrid grid_;
};

}  // namespace lampnav::fusion::detail
