#pragma once
// Points of the plane in a grid of cells over their box, the cells one array row by row (no
// hashing): "which points may lie within r of p?", asked tens of thousands of times a frame by
// the global localizer (the map's lamps, global_localizer_impl.hpp) and the hypothesis set (the
// places carried between images, pose_grid.hpp).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace lampnav::fusion::detail {

class FlatGrid {
 public:
  FlatGrid() = default;
  // Cells of `cell` (at least 1 mm), grown until there are at most `max_cells`. Points that are
  // not finite are left out: no distance to them is within a radius.
  FlatGrid(const std::vector<Eigen::Vector2d>& points, double cell, double max_cells) {
    bool any = false;
    Eigen::Vector2d lo(0, 0), hi(0, 0);
    for (const Eigen::Vector2d& p : points) {
      if (!p.allFinite()) continue;
      lo = any ? lo.cwiseMin(p) : p;
      hi = any ? hi.cwiseMax(p) : p;
      any = true;
    }
    if (!any) return;
    const Eigen::Vector2d extent = (hi - lo).cwiseMax(Eigen::Vector2d(1e-3, 1e-3));
    cell_ = std::max(
        {cell, 1e-3, std::sqrt(extent.x() * extent.y() / max_cells), extent.maxCoeff() / 4096});
    origin_ = lo;
    columns_ = static_cast<int>(extent.x() / cell_) + 1;
    rows_ = static_cast<int>(extent.y() / cell_) + 1;
    std::vector<int> cell_of(points.size(), -1);
    start_.assign(static_cast<std::size_t>(columns_) * rows_ + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!points[i].allFinite()) continue;
      const Eigen::Vector2d q = (points[i] - lo) / cell_;
      cell_of[i] = std::min(rows_ - 1, static_cast<int>(q.y())) * columns_ +
                   std::min(columns_ - 1, static_cast<int>(q.x()));
      ++start_[cell_of[i] + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    index_.resize(static_cast<std::size_t>(start_.back()));
    for (std::size_t i = 0; i < points.size(); ++i)
      if (cell_of[i] >= 0) index_[fill[cell_of[i]]++] = static_cast<int>(i);
  }

  // Calls f(i) for the points i of the cells that meet the square of side 2 r around p, each
  // cell's in the order given (the caller tests the distance).
  template <class F>
  void visit(const Eigen::Vector2d& p, double r, F&& f) const {
    if (index_.empty()) return;
    const Eigen::Vector2d a = (p - Eigen::Vector2d(r, r) - origin_) / cell_;
    const Eigen::Vector2d b = (p + Eigen::Vector2d(r, r) - origin_) / cell_;
    // Outside the box, or not finite: no point is near.
    if (!(b.x() >= 0 && b.y() >= 0 && a.x() < columns_ && a.y() < rows_)) return;
    auto at = [](double v, int n) { return static_cast<int>(std::clamp(v, 0.0, n - 1.0)); };
    const int x0 = at(a.x(), columns_), x1 = at(b.x(), columns_);
    const int y0 = at(a.y(), rows_), y1 = at(b.y(), rows_);
    for (int y = y0; y <= y1; ++y)
      for (int k = start_[y * columns_ + x0]; k < start_[y * columns_ + x1 + 1]; ++k) f(index_[k]);
  }

 private:
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_ = 1;
  int columns_ = 0, rows_ = 0;
  std::vector<int> start_;  // per cell, into index_; one more at the end
  std::vector<int> index_;  // point indices, cell by cell
};

}  // namespace lampnav::fusion::detail
