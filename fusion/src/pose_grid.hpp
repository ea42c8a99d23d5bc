#pragma once
// Poses in a grid of cells, to ask "which of them lie within r metres and a radians of this
// one?": the places an earlier image allowed, carried to the next one (the enumeration's prior
// and its bookkeeping, global_localizer.hpp and hypothesis_set.cpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
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
      : poses_(&poses), values_(values), cell_(std::max(reach_m, 0.05)) {
    if (poses.empty()) return;
    // An enumeration asks some 40,000 times: over the poses' own box the cells are one array
    // (no hashing), unless that box is too big for its poses (poses far apart, or not finite).
    // A 1,000-node building's places take 40,000 to 90,000 cells of a gate (0.5 MB at most).
    Eigen::Vector2d lo = poses.front().translation(), hi = lo;
    for (const Pose2& p : poses) {
      lo = lo.cwiseMin(p.translation());
      hi = hi.cwiseMax(p.translation());
    }
    const double columns = std::floor((hi.x() - lo.x()) / cell_) + 1;
    const double rows = std::floor((hi.y() - lo.y()) / cell_) + 1;
    const double limit = std::max(double(1 << 17), 16.0 * static_cast<double>(poses.size()));
    if (columns * rows <= limit) {  // false for NaN too
      origin_ = lo;
      columns_ = static_cast<int>(columns);
      rows_ = static_cast<int>(rows);
      start_.assign(static_cast<std::size_t>(columns_) * rows_ + 1, 0);
      std::vector<int> cell_of(poses.size());
      for (std::size_t k = 0; k < poses.size(); ++k) {
        cell_of[k] = cell(poses[k].translation());
        ++start_[cell_of[k] + 1];
      }
      for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
      std::vector<int> next(start_.begin(), start_.end() - 1);
      index_.resize(poses.size());
      for (std::size_t k = 0; k < poses.size(); ++k) index_[next[cell_of[k]]++] = int(k);
    } else {
      index_map_.emplace(cell_);
      for (std::size_t k = 0; k < poses.size(); ++k)
        index_map_->insert({poses[k].translation(), poses[k].translation()}, k);
    }
  }

  // Whether a pose of the grid lies within r_m and r_rad of p.
  bool near(const Pose2& p, double r_m, double r_rad) const {
    return least(p, r_m, r_rad) < std::numeric_limits<double>::infinity();
  }
  // The least value of the poses within r_m and r_rad of p (0 without values); infinity when
  // there is none.
  double least(const Pose2& p, double r_m, double r_rad) const {
    double best = std::numeric_limits<double>::infinity();
    const auto consider = [&](std::size_t k) {
      const Pose2& q = (*poses_)[k];
      if ((q.translation() - p.translation()).squaredNorm() <= r_m * r_m &&
          std::abs(wrap_angle(q.yaw() - p.yaw())) <= r_rad)
        best = std::min(best, values_ ? (*values_)[k] : 0.0);
    };
    const Eigen::Vector2d r(r_m, r_m);
    if (index_map_) {
      index_map_->query({p.translation() - r, p.translation() + r}, consider);
      return best;
    }
    if (columns_ == 0) return best;
    const Eigen::Vector2d a = (p.translation() - r - origin_) / cell_;
    const Eigen::Vector2d b = (p.translation() + r - origin_) / cell_;
    // Outside the poses' box (or not finite): no pose is near.
    if (!(b.x() >= 0 && b.y() >= 0 && a.x() < columns_ && a.y() < rows_)) return best;
    const int x0 = clamped(a.x(), columns_), x1 = clamped(b.x(), columns_);
    const int y0 = clamped(a.y(), rows_), y1 = clamped(b.y(), rows_);
    for (int y = y0; y <= y1; ++y) {
      const int row = y * columns_;
      for (int k = start_[row + x0]; k < start_[row + x1 + 1]; ++k) consider(index_[k]);
    }
    return best;
  }

 private:
  static int clamped(double v, int n) {
    return static_cast<int>(std::clamp(std::floor(v), 0.0, n - 1.0));
  }
  int cell(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d c = (p - origin_) / cell_;
    return clamped(c.y(), rows_) * columns_ + clamped(c.x(), columns_);
  }
  const std::vector<Pose2>* poses_;
  const std::vector<double>* values_;
  double cell_;
  // The dense grid: cells row by row over [origin_, origin_ + cell_ * (columns_, rows_)].
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int columns_ = 0, rows_ = 0;
  std::vector<int> start_, index_;             // per cell, into index_; one more at the end
  std::optional<graph::GridIndex> index_map_;  // when the dense grid would be too big
};

}  // namespace lampnav::fusion::detail
