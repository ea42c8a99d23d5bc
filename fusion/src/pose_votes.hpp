#pragma once
// Votes for poses (the lamp-pair search, lamp_pairs.cpp): each pose votes for its cell of 0.25 m
// x 3 degrees, and a place's votes are those of its cell. A single grid splits poses that agree
// but lie across a cell's border: three pairs of lamps that put the robot within a few
// centimetres of one place can give three cells one vote each, behind look-alike places whose
// two votes fell in one cell. So the votes are counted in eight grids, shifted by half a cell
// along each of x, y and yaw: poses that agree to within half a cell share a cell in one of them
// whatever their place against the borders, and a place is as many votes as its best cell holds.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::fusion::detail {

// floor(v) as an integer, clamped first so that no coordinate converts out of range (NaN: 0).
// Cells' keys are built from these in unsigned arithmetic: a map thousands of kilometres across
// wraps a key instead of overflowing it (the same key as signed arithmetic gives wherever that
// does not overflow).
inline std::int64_t clamped_floor(double v) {
  return v == v ? std::int64_t(std::floor(std::clamp(v, -1e15, 1e15))) : 0;
}

// The key of cell (x, y, a): x and y the cell's indices along the axes, a along yaw (unsigned:
// wraps, never overflows).
inline std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t a) {
  return (std::uint64_t(x) * 1000003u + std::uint64_t(y)) * 1009u + std::uint64_t(a);
}

class PoseVotes {
 public:
  PoseVotes();
  ~PoseVotes();
  PoseVotes(const PoseVotes&) = delete;
  PoseVotes& operator=(const PoseVotes&) = delete;
  static constexpr double kCellM = 0.25;
  static constexpr double kCellDeg = 3.0;

  void add(const Pose2& pose) { poses_.push_back(pose); }

  struct Place {
    int votes = 0;
    Pose2 pose;  // the mean of the poses of its cell
  };
  // The places with the most votes, most first (ties by cell, so that the order never depends on
  // a hash table's), at most `n`, each once however many grids' cells hold it.
  std::vector<Place> best(std::size_t n);
  // How many places hold at least `votes` in a cell, each once; counting stops past `limit`.
  std::size_t places_with_at_least(int votes, std::size_t limit);

 private:
  struct Cell {
    int votes = 0;
    int pose = 0;  // votes == 1: that pose; else the index of its mean in means_
    std::int64_t key = 0;
  };
  void count();
  static std::vector<Cell>& spare();  // this thread's cells, kept between searches
  Pose2 pose_of(const Cell& c) const { return c.votes == 1 ? poses_[c.pose] : means_[c.pose]; }

  std::vector<Pose2> poses_;
  std::vector<Cell> cells_;  // every grid's, once counted
  std::vector<Pose2> means_;
  bool counted_ = false;
};

}  // namespace lampnav::fusion::detail
