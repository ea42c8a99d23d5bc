#include "lampnav/graph/grid_index.hpp"

namespace lampnav::graph {

void GridIndex::insert(const Box2& box, std::size_t index) {
  const auto [x0, y0] = cell_of(box.min);
  const auto [x1, y1] = cell_of(box.max);
  if (double(x1 - x0 + 1) * double(y1 - y0 + 1) > kMaxCells) {
    oversize_.push_back(index);
    return;
  }
  for (std::int64_t x = x0; x <= x1; ++x) {
    for (std::int64_t y = y0; y <= y1; ++y) cells_[key(x, y)].push_back(index);
  }
}

}  // namespace lampnav::graph
