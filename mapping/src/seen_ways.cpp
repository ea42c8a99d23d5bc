#include "seen_ways.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "median.hpp"
#include "omni_ways.hpp"

namespace lampnav::mapping::drive_topology {

using Eigen::Vector2d;

namespace {

// Signed offset of `p` across `L` (positive to the right of its direction).
double signed_across(const Line& L, const Vector2d& p) {
  const Vector2d d = p - L.origin;
  return d.x() * L.dir.y() - d.y() * L.dir.x();
}

// Where the lamps the drive passed under stand across and along run `r` of `L`: those within
// rows_reach_m of its line and along it, for a run of at least 4 of them (else nothing). Their
// signed offsets' 10th and 90th percentiles (`lo`, `hi`), and where along the line the first and
// last of them are.
struct MappedSpread {
  double lo = 0, hi = 0, s0 = 0, s1 = 0;
  std::size_t lamps = 0;
};

std::optional<MappedSpread> mapped_spread(const Line& L, const Run& r,
                                          const std::vector<MappedLamp>& lamps,
                                          const TopologyOptions& o) {
  std::vector<double> across;
  MappedSpread m;
  for (const MappedLamp& l : lamps) {
    const Vector2d p = l.xyz.head<2>();
    const double s = L.along(p), a = signed_across(L, p);
    if (s < r.s0 || s > r.s1 || std::abs(a) > o.rows_reach_m) continue;
    m.s0 = across.empty() ? s : std::min(m.s0, s);
    m.s1 = across.empty() ? s : std::max(m.s1, s);
    across.push_back(a);
  }
  if (across.size() < 4) return std::nullopt;
  std::sort(across.begin(), across.end());
  const std::size_t n = across.size() - 1;
  m.lo = across[n / 10];
  m.hi = across[n - n / 10];
  m.lamps = across.size();
  return m;
}

// Where a corridor's lamps stand across it, from the lamps the drive passed under (their signed
// offsets from each run's line, right positive: mapped_spread). `centre`, per run: the middle of
// their spread, 0 for a run of fewer than 4 lamps; near 0 where the robot drives under a row,
// 0.7 m where the lamps hang to one side of the corridor and the robot drives down its middle.
// `half_spread`: half that spread, the median over runs; near 0 for one row (the robot weaves a
// little), half the rows' spacing for two (a wide corridor's two rows of troffers).
struct RowsAcross {
  double half_spread = 0;
  std::vector<double> centre;
};

RowsAcross rows_across(const std::vector<Line>& lines, const std::vector<Run>& runs,
                       const std::vector<MappedLamp>& lamps, const TopologyOptions& o) {
  RowsAcross out;
  std::vector<double> halves;
  for (const auto& r : runs) {
    const auto m = mapped_spread(lines[r.line], r, lamps, o);
    out.centre.push_back(m ? (m->hi + m->lo) / 2 : 0.0);
    if (m) halves.push_back((m->hi - m->lo) / 2);
  }
  out.half_spread = halves.empty() ? 0.0 : median(halves);
  return out;
}

}  // namespace

std::vector<RowBeside> rows_beside(const std::vector<Line>& lines, const std::vector<Run>& runs,
                                   const std::vector<MappedLamp>& lamps,
                                   const std::vector<Vector2d>& seen, const TopologyOptions& o) {
  // From the mapped row; between a row's lamps, across; between two lamps of a row, along.
  constexpr double kClear = 0.5, kGap = 0.4, kSame = 1.0;
  std::vector<RowBeside> out;
  std::vector<std::pair<double, double>> near;  // seen beside: (offset, along)
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const Line& L = lines[runs[k].line];
    const auto m = mapped_spread(L, runs[k], lamps, o);
    if (!m) continue;
    const double lo = m->lo, hi = m->hi;
    near.clear();
    for (const Vector2d& p : seen) {
      const double s = L.along(p), across = signed_across(L, p);
      if (s >= m->s0 && s <= m->s1 && std::abs(across) <= o.row_beside_m &&
          (across < lo - kClear || across > hi + kClear))
        near.push_back({across, s});
    }
    std::sort(near.begin(), near.end());
    // The mapped row's spacing; the other row's lamps are as close. A room's grid beside a
    // corridor is sparser: the generated buildings' rooms have their nearest row of lamps 2.4 m
    // off the corridor's axis, 4 m apart against the corridor's 2.25 m.
    const double spacing = (m->s1 - m->s0) / double(m->lamps - 1);
    RowBeside best;
    std::vector<double> at;
    for (std::size_t a = 0, b = 0; a < near.size(); a = b) {
      at = {near[a].second};
      for (b = a + 1; b < near.size() && near[b].first - near[b - 1].first <= kGap; ++b)
        at.push_back(near[b].second);
      // Lamps, not sightings: the omni camera's lamps along the row more than kSame apart.
      std::sort(at.begin(), at.end());
      int count = 1;
      for (std::size_t i = 1; i < at.size(); ++i) count += at[i] - at[i - 1] > kSame;
      const double length = at.back() - at.front();
      if (count < 4 || length < 0.5 * (m->s1 - m->s0) || length / (count - 1) > 1.5 * spacing ||
          count <= best.lamps)
        continue;
      const double other = near[a + (b - a) / 2].first, mine = other > hi ? hi : lo;
      const Vector2d right(L.dir.y(), -L.dir.x());
      best.run = static_cast<int>(k);
      best.middle = L.at(0.5 * (m->s0 + m->s1)) + 0.5 * (lo + hi) * right;
      best.towards = other > hi ? right : Vector2d(-right);
      best.offset = other;
      best.apart_m = std::abs(other - mine);
      best.s0 = at.front();
      best.s1 = at.back();
      best.lamps = count;
    }
    if (best.lamps > 0) out.push_back(best);
  }
  return out;
}

std::vector<SeenWay> ways_not_driven(const std::vector<Line>& lines, const std::vector<Run>& runs,
                                     const std::vector<MappedLamp>& lamps,
                                     const std::vector<Vector2d>& seen,
                                     const std::vector<RowBeside>& other_rows,
                                     const TopologyOptions& o) {
  std::vector<SeenWay> out;
  if (o.way_min_lamps == 0 || seen.empty()) return out;
  // Corridors of two rows (or more): a way's lamps stand in a band as wide as the driven
  // corridors' rows, not on one line; the omni camera sees a far pair of lamps side by side as one
  // blob between them, a near pair as two. The band is 0 for one row.
  const RowsAcross rows = rows_across(lines, runs, lamps, o);
  const double band = rows.half_spread > o.way_across_m ? rows.half_spread : 0.0;
  const double across = o.way_across_m + band;
  // A run's own lamps: near the middle of its lamps' band, along it.
  std::vector<Vector2d> around;
  for (const Vector2d& p : seen) {
    bool own = false;
    for (std::size_t k = 0; k < runs.size(); ++k) {
      const Run& r = runs[k];
      const Line& L = lines[r.line];
      const double s = L.along(p), across_run = signed_across(L, p);
      const bool along = s > r.s0 - o.place_m && s < r.s1 + o.place_m;
      own = own || (along && std::abs(across_run - rows.centre[k]) < o.same_line_m + band);
    }
    // The other row of a corridor driven under one of its two: its own too.
    for (const RowBeside& b : other_rows) {
      const Line& L = lines[runs[b.run].line];
      const double s = L.along(p);
      own = own || (s > b.s0 - 0.5 && s < b.s1 + 0.5 &&
                    std::abs(signed_across(L, p) - b.offset) < o.same_line_m);
    }
    if (!own) around.push_back(p);
  }
  // Corridors driven under one of their two rows: their ways out have two rows as well, as far
  // apart as the rows beside the runs (the other row is no room's lamps beside a way).
  std::vector<double> halves;
  for (const RowBeside& b : other_rows) halves.push_back(b.apart_m / 2);
  const double rows_band = std::max(band, halves.empty() ? 0.0 : median(halves));
  const double min_sin = std::sin(o.way_min_angle_deg * M_PI / 180);
  for (const LampRow& row : lamp_rows(around, o.way_min_lamps, across, o.way_gap_m)) {
    const Vector2d u = row.dir();
    // A corridor's row has at most a lamp beside it (a room's, through a door): lamps off the
    // row's line but near it (a column or a diagonal of a room's grid of lamps) make it no way.
    // A corridor of two rows has its other row beside it, within the band of its rows.
    const double length = (row.last - row.first).norm();
    int beside = 0;
    for (const Vector2d& p : around) {
      const Vector2d e = p - row.first;
      const double off = std::abs(u.x() * e.y() - u.y() * e.x()), s = u.dot(e);
      beside += off > 4 * o.way_across_m + 2 * rows_band && off < o.way_clear_m &&
                s > -o.way_clear_m && s < length + o.way_clear_m;
    }
    if (beside > 1) continue;
    for (const auto& r : runs) {
      const Line& L = lines[r.line];
      const double cross = L.dir.x() * u.y() - L.dir.y() * u.x();
      if (std::abs(cross) < min_sin) continue;
      // Where the row's line meets the run's, and the row's ends from there along the row.
      const Vector2d d = row.first - L.origin;
      const double s = (d.x() * u.y() - d.y() * u.x()) / cross;
      if (s < r.s0 - o.place_m || s > r.s1 + o.place_m) continue;
      const Vector2d at = L.at(s);
      const double a = (row.first - at).dot(u), b = (row.last - at).dot(u);
      if (a * b <= 0 || std::min(std::abs(a), std::abs(b)) > o.way_first_lamp_m) continue;
      out.push_back({at, a > 0 ? u : Vector2d(-u), 0.5 * (row.first + row.last), row.lamps});
    }
  }
  // A corridor's lamps are one row (or one band of rows); rows side by side going the same way (a
  // room's or a hall's grid of lamps, seen through walls or a door) are no way out.
  const double same_way = std::cos(15 * M_PI / 180);
  std::vector<SeenWay> alone;
  for (const SeenWay& x : out) {
    bool beside = false;
    for (const SeenWay& y : out) {
      // Apart across the way (rows through some of the same lamps are not side by side).
      const Vector2d e = y.middle - x.at;
      const double apart = std::abs(x.way.x() * e.y() - x.way.y() * e.x());
      beside =
          beside || (y.way.dot(x.way) > same_way && apart > across + 0.7 && apart < o.way_beside_m);
    }
    if (!beside) alone.push_back(x);
  }
  if (rows_band == 0) return alone;
  // In a band of rows, few lamps are seen down a way (a far pair is one blob), and lines through a
  // lamp of one row and the next of the other hold as many as the band's own: each way is found
  // several times, askew by up to 30 degrees, crossing the run up to 2 m from where it meets it.
  // Ways within 50 degrees of each other crossing within twice a place's size are one, along
  // their mean (weighted by their lamps), from the mean of their crossings.
  const double alike = std::cos(50 * M_PI / 180),
               reach = 2 * std::max(o.place_m, o.corridor_width_m);
  std::stable_sort(alone.begin(), alone.end(),
                   [](const SeenWay& x, const SeenWay& y) { return x.lamps > y.lamps; });
  struct Group {
    SeenWay first;
    Vector2d at = Vector2d::Zero(), way = Vector2d::Zero(), middle = Vector2d::Zero();
    double weight = 0;
  };
  std::vector<Group> groups;
  for (const SeenWay& x : alone) {
    Group* g = nullptr;
    for (Group& h : groups)
      if (!g && (h.first.at - x.at).norm() < reach && h.first.way.dot(x.way) > alike) g = &h;
    if (!g) {
      groups.push_back({x});
      g = &groups.back();
    }
    g->at += x.lamps * x.at;
    g->way += x.lamps * x.way;
    g->middle += x.lamps * x.middle;
    g->weight += x.lamps;
  }
  std::vector<SeenWay> kept;
  for (const Group& g : groups) {
    if (band > 0)
      kept.push_back({g.at / g.weight, g.way.normalized(), g.middle / g.weight, g.first.lamps});
    else  // the drive mapped one of the rows: the way with the most lamps
      kept.push_back(g.first);
  }
  return kept;
}

}  // namespace lampnav::mapping::drive_topology
