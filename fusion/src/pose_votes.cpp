#include "pose_votes.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace lampnav::fusion::detail {

namespace {

constexpr int kGrids = 8;
constexpr double kCellRad = PoseVotes::kCellDeg * M_PI / 180;
constexpr std::int64_t kTurn = 120;  // yaw cells in a turn: 360 / 3 degrees

// Two places within a cell of each other along every axis: one place.
bool same_place(const Pose2& a, const Pose2& b) {
  return std::abs(a.x() - b.x()) < PoseVotes::kCellM &&
         std::abs(a.y() - b.y()) < PoseVotes::kCellM &&
         std::abs(wrap_angle(a.yaw() - b.yaw())) < kCellRad;
}

// The places kept so far, looked up by their 0.25 m square: a place within a cell of another
// lies in one of the nine squares around it.
class Distinct {
 public:
  // Whether p is a place not seen yet; if so it is kept.
  bool insert(const Pose2& p) {
    const std::int64_t ix = clamped_floor(p.x() / PoseVotes::kCellM);
    const std::int64_t iy = clamped_floor(p.y() / PoseVotes::kCellM);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = squares_.find(key(ix + dx, iy + dy));
        if (it == squares_.end()) continue;
        for (const Pose2& q : it->second)
          if (same_place(p, q)) return false;
      }
    squares_[key(ix, iy)].push_back(p);
    return true;
  }

 private:
  static std::int64_t key(std::int64_t ix, std::int64_t iy) {
    return static_cast<std::int64_t>(std::uint64_t(ix) * 1000003u + std::uint64_t(iy));
  }
  std::unordered_map<std::int64_t, std::vector<Pose2>> squares_;
};

// A cell of one grid in an open-addressed table, its poses chained through `next`. The table
// and the chain are kept by each thread from one search to the next (a grid's cells are about
// one a pose: 14,000 poses on a 1,000-node building), so that no search pays for fresh pages.
struct Slot {
  std::int64_t key = 0;
  int votes = 0;
  int head = 0;  // its last pose; the others through next[]
};

std::uint64_t mix(std::int64_t k) {
  std::uint64_t z = std::uint64_t(k) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// floor(a / 2) for any sign.
std::int64_t half_down(std::int64_t a) { return a >= 0 ? a / 2 : -((1 - a) / 2); }

}  // namespace

std::vector<PoseVotes::Cell>& PoseVotes::spare() {
  thread_local std::vector<Cell> cells;
  return cells;
}

PoseVotes::PoseVotes() {
  cells_.swap(spare());
  cells_.clear();
}

PoseVotes::~PoseVotes() {
  if (cells_.capacity() > spare().capacity()) cells_.swap(spare());
}

void PoseVotes::count() {
  counted_ = true;
  cells_.clear();
  means_.clear();
  const std::size_t n = poses_.size();
  if (n == 0) return;
  // Each pose in half cells: a grid shifted by half a cell along an axis holds half cells 2k - 1
  // and 2k in its cell k, one not shifted 2k and 2k + 1.
  struct Halves {
    std::int64_t x, y, a;
  };
  std::vector<Halves> halves(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Pose2& p = poses_[i];
    halves[i] = {clamped_floor(2 * p.x() / kCellM), clamped_floor(2 * p.y() / kCellM),
                 clamped_floor(2 * (p.yaw() + M_PI) / kCellRad)};
  }
  std::size_t capacity = 16;
  while (capacity < 2 * n) capacity *= 2;
  const std::size_t mask = capacity - 1;
  thread_local std::vector<Slot> table;  // clean between searches: used slots are reset
  thread_local std::vector<int> next;
  if (table.size() < capacity) table.resize(capacity);
  if (next.size() < n) next.resize(n);
  std::vector<std::size_t> used;
  used.reserve(n);
  cells_.reserve(kGrids * n);
  for (int g = 0; g < kGrids; ++g) {
    const int sx = g & 1, sy = (g >> 1) & 1, sa = (g >> 2) & 1;
    for (std::size_t i = 0; i < n; ++i) {
      const Halves& p = halves[i];
      const std::int64_t a = half_down(p.a + sa);
      const std::uint64_t u =
          cell_key(half_down(p.x + sx), half_down(p.y + sy), a >= kTurn ? a - kTurn : a) * kGrids +
          std::uint64_t(g);
      const std::int64_t key = static_cast<std::int64_t>(u);
      std::size_t h = mix(key) & mask;
      while (table[h].votes != 0 && table[h].key != key) h = (h + 1) & mask;
      Slot& slot = table[h];
      if (slot.votes == 0) {
        slot.key = key;
        used.push_back(h);
        next[i] = -1;
      } else {
        next[i] = slot.head;
      }
      ++slot.votes;
      slot.head = int(i);
    }
    for (std::size_t h : used) {
      Slot& slot = table[h];
      Cell cell{slot.votes, slot.head, slot.key};
      if (slot.votes > 1) {
        double x = 0, y = 0, c = 0, s = 0;
        for (int i = slot.head; i >= 0; i = next[i]) {
          x += poses_[i].x();
          y += poses_[i].y();
          c += std::cos(poses_[i].yaw());
          s += std::sin(poses_[i].yaw());
        }
        cell.pose = int(means_.size());
        means_.emplace_back(x / slot.votes, y / slot.votes, std::atan2(s, c));
      }
      cells_.push_back(cell);
      slot = Slot{};
    }
    used.clear();
  }
}

std::vector<PoseVotes::Place> PoseVotes::best(std::size_t n) {
  if (!counted_) count();
  auto better = [](const Cell& a, const Cell& b) {
    return a.votes != b.votes ? a.votes > b.votes : a.key < b.key;
  };
  std::vector<Place> out;
  // A place holds a cell in up to eight grids: sort enough cells for n places, and more if
  // the places they hold were fewer.
  std::size_t sorted = 0;
  Distinct seen;
  for (std::size_t want = kGrids * n; out.size() < n && sorted < cells_.size(); want *= 2) {
    const std::size_t keep = std::min(cells_.size(), want);
    if (keep < cells_.size())
      std::nth_element(cells_.begin() + sorted, cells_.begin() + keep, cells_.end(), better);
    std::sort(cells_.begin() + sorted, cells_.begin() + keep, better);
    for (; sorted < keep && out.size() < n; ++sorted) {
      const Cell& c = cells_[sorted];
      const Pose2 p = pose_of(c);
      if (seen.insert(p)) out.push_back({c.votes, p});
    }
  }
  return out;
}

std::size_t PoseVotes::places_with_at_least(int votes, std::size_t limit) {
  if (!counted_) count();
  std::size_t n = 0;
  Distinct seen;
  for (const Cell& c : cells_)
    if (c.votes >= votes && seen.insert(pose_of(c)) && ++n > limit) break;
  return n;
}

}  // namespace lampnav::fusion::detail
