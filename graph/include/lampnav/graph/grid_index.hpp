#pragma once
// The map's spatial index, also used by the places the localizer carries between images.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "lampnav/graph/geometry.hpp"

namespace lampnav::graph {

// A uniform grid over the plane holding indexes of things by the cells their boxes cover. A box
// wider than kMaxCells cells (a region kilometres across, from a map in the wrong units) is kept
// aside and returned by every query, and a query wider than the cells held walks the cells held:
// no box costs more memory or time than the map's own size.
class GridIndex {
 public:
  explicit GridIndex(double cell = 4.0) : cell_(cell) {}
  void insert(const Box2& box, std::size_t index);
  // Calls f(index) for every index whose box may meet `box` (an index may come more than once).
  template <class F>
  void query(const Box2& box, F&& f) const {
    const auto [x0, y0] = cell_of(box.min);
    const auto [x1, y1] = cell_of(box.max);
    if (double(x1 - x0 + 1) * double(y1 - y0 + 1) > double(cells_.size())) {
      for (const auto& [k, indexes] : cells_)
        for (std::size_t i : indexes) f(i);
    } else {
      for (std::int64_t x = x0; x <= x1; ++x) {
        for (std::int64_t y = y0; y <= y1; ++y) {
          auto it = cells_.find(key(x, y));
          if (it == cells_.end()) continue;
          for (std::size_t i : it->second) f(i);
        }
      }
    }
    for (std::size_t i : oversize_) f(i);
  }

 private:
  static constexpr double kMaxCells = 4096;
  std::pair<std::int64_t, std::int64_t> cell_of(const Eigen::Vector2d& p) const {
    // Far coordinates share the outermost cells (and a cast never overflows).
    auto c = [&](double v) {
      const double f = std::floor(v / cell_);
      return static_cast<std::int64_t>(std::isfinite(f) ? std::clamp(f, -1e9, 1e9) : 0.0);
    };
    return {c(p.x()), c(p.y())};
  }
  static std::uint64_t key(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffULL);
  }
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> oversize_;
};

}  // namespace lampnav::graph
