#include "halls.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace lampnav::mapping::drive_topology {

using Eigen::Vector2d;

namespace {

// The hull of the points grown by r (each point as an octagon around it).
graph::Polygon grown_hull(const std::vector<Vector2d>& pts, double r) {
  std::vector<Vector2d> around;
  for (const auto& p : pts)
    for (int k = 0; k < 8; ++k)
      around.push_back(p + r * Vector2d(std::cos(k * M_PI / 4), std::sin(k * M_PI / 4)));
  return graph::convex_hull(around);
}

// The connected components of n items linked pairwise by `linked` (single linkage): each item's
// component, named by one of its items.
template <typename Linked>
std::vector<std::size_t> components(std::size_t n, const Linked& linked) {
  std::vector<std::size_t> group(n);
  for (std::size_t i = 0; i < n; ++i) group[i] = i;
  auto root = [&](std::size_t i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (root(i) != root(j) && linked(i, j)) group[root(i)] = root(j);
  for (std::size_t i = 0; i < n; ++i) group[i] = root(i);
  return group;
}

// Where a line is inside a convex counter-clockwise polygon, as distances along it (lo >= hi:
// nowhere).
std::pair<double, double> inside(const Line& L, const graph::Polygon& P) {
  double lo = -1e300, hi = 1e300;
  const auto& v = P.vertices();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vector2d e = v[(i + 1) % v.size()] - v[i];
    const Vector2d out(e.y(), -e.x());  // the outward normal of a counter-clockwise edge
    const double num = out.dot(L.origin - v[i]), den = out.dot(L.dir);
    if (std::abs(den) < 1e-12) {
      if (num > 0) return {0, 0};
      continue;
    }
    if (den > 0)
      hi = std::min(hi, -num / den);
    else
      lo = std::max(lo, -num / den);
  }
  return {lo, hi};
}

// The rows of lamps across a lane, from their offsets across it (sorted): clusters of two lamps
// or more whose gaps are under 0.3 m (a corridor crossing the lanes has one lamp in each lane),
// each as its first and last offset.
std::vector<std::pair<double, double>> rows_of(const std::vector<double>& off) {
  std::vector<std::pair<double, double>> rows;
  for (std::size_t i = 0, j = 0; i < off.size(); i = j) {
    for (j = i + 1; j < off.size() && off[j] - off[j - 1] < 0.3;) ++j;
    if (j - i >= 2) rows.emplace_back(off[i], off[j - 1]);
  }
  return rows;
}

}  // namespace

std::vector<double> join_lanes_under_two_rows(std::vector<Line>& lines,
                                              const std::vector<MappedLamp>& lamps,
                                              const TopologyOptions& o) {
  const double parallel = std::sin(o.parallel_deg * M_PI / 180);
  std::vector<double> joined;
  for (std::size_t i = 0; i < lines.size(); ++i)
    for (std::size_t j = i + 1; j < lines.size(); ++j) {
      Line &A = lines[i], &B = lines[j];
      if (std::abs(A.dir.x() * B.dir.y() - A.dir.y() * B.dir.x()) > parallel) continue;
      const double gap = A.across(B.origin);
      if (gap <= o.same_line_m || gap > o.row_beside_m) continue;
      // Where both were driven side by side, along A.
      double lo = 1e300, hi = -1e300, overlap = 0;
      for (const auto& [a0, a1] : A.intervals)
        for (const auto& [b0, b1] : B.intervals) {
          const double p = A.along(B.at(b0)), q = A.along(B.at(b1));
          const double l = std::max(a0, std::min(p, q)), h = std::min(a1, std::max(p, q));
          if (h - l <= 0) continue;
          overlap += h - l;
          lo = std::min(lo, l);
          hi = std::max(hi, h);
        }
      if (overlap < o.hall_min_overlap_m) continue;
      // The mapped lamps there, within row_beside_m outside either lane, by their offset from A
      // towards B: a hall driven in lanes has more rows of lamps beside them.
      const Vector2d n = Vector2d(-A.dir.y(), A.dir.x()) *
                         ((B.origin - A.origin).dot(Vector2d(-A.dir.y(), A.dir.x())) < 0 ? -1 : 1);
      std::vector<double> off;
      for (const MappedLamp& l : lamps) {
        const Vector2d p = l.xyz.head<2>();
        const double s = A.along(p), t = n.dot(p - A.origin);
        if (s >= lo && s <= hi && t > -o.row_beside_m && t < gap + o.row_beside_m) off.push_back(t);
      }
      std::sort(off.begin(), off.end());
      const auto rows = rows_of(off);
      const auto middle = [&](std::size_t k) { return 0.5 * (rows[k].first + rows[k].second); };
      if (rows.size() != 2 || std::abs(middle(0)) > o.same_line_m ||
          std::abs(middle(1) - gap) > o.same_line_m)
        continue;
      // One line half way between, with both lines' stretches.
      Line mid{A.origin + 0.5 * gap * n, A.dir, {}};
      for (const Line* L : {&A, &B})
        for (const auto& [s0, s1] : L->intervals) {
          const double p = mid.along(L->at(s0)), q = mid.along(L->at(s1));
          mid.intervals.emplace_back(std::min(p, q), std::max(p, q));
        }
      A = mid;
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(j));
      --j;
      joined.push_back(middle(1) - middle(0));
    }
  return joined;
}

// Lanes are pieces of runs of two different lines, parallel, side by side over more than
// hall_min_overlap_m, further apart than same_line_m and at most hall_lane_gap_m. A hall's region
// is the hull of its lanes and the lamps around them, grown by the margin.
std::vector<graph::Polygon> halls_from_lanes(const std::vector<Line>& lines,
                                             const std::vector<Run>& runs,
                                             const std::vector<MappedLamp>& lamps,
                                             const TopologyOptions& o) {
  std::vector<graph::Polygon> halls;
  if (o.hall_lane_gap_m <= 0) return halls;
  const double parallel = std::sin(o.parallel_deg * M_PI / 180);
  std::vector<std::pair<Vector2d, Vector2d>> lanes;
  for (std::size_t i = 0; i < runs.size(); ++i)
    for (std::size_t j = i + 1; j < runs.size(); ++j) {
      if (runs[i].line == runs[j].line) continue;
      const Line &A = lines[runs[i].line], &B = lines[runs[j].line];
      if (std::abs(A.dir.x() * B.dir.y() - A.dir.y() * B.dir.x()) > parallel) continue;
      const double b0 = A.along(B.at(runs[j].s0)), b1 = A.along(B.at(runs[j].s1));
      const double lo = std::max(runs[i].s0, std::min(b0, b1));
      const double hi = std::min(runs[i].s1, std::max(b0, b1));
      if (hi - lo < o.hall_min_overlap_m) continue;
      const Vector2d pa = A.at(lo), pb = A.at(hi);
      const Vector2d qa = B.at(B.along(pa)), qb = B.at(B.along(pb));
      const double gap = 0.5 * ((qa - pa).norm() + (qb - pb).norm());
      if (gap <= o.same_line_m || gap > o.hall_lane_gap_m) continue;
      lanes.emplace_back(pa, pb);
      lanes.emplace_back(qa, qb);
    }
  // Lanes that touch (a pair's two, and lanes of pairs that share a stretch) are one group.
  const auto root = components(lanes.size(), [&](std::size_t i, std::size_t j) {
    return graph::segment_distance(lanes[i].first, lanes[i].second, lanes[j].first,
                                   lanes[j].second) <= o.hall_lane_gap_m;
  });
  std::vector<std::vector<Vector2d>> members;
  std::map<std::size_t, std::size_t> index;
  for (std::size_t i = 0; i < lanes.size(); ++i) {
    const auto [it, added] = index.emplace(root[i], members.size());
    if (added) members.emplace_back();
    members[it->second].push_back(lanes[i].first);
    members[it->second].push_back(lanes[i].second);
  }
  std::vector<std::vector<Vector2d>> kept;
  for (auto& pts : members) {
    // The lamps the lanes pass under or beside (half a lane gap out), in rows along the lanes
    // (two lamps or more a row: a corridor crossing the lanes has one lamp in each), and how far
    // apart the outer rows are.
    const graph::Polygon reach = grown_hull(pts, 0.5 * o.hall_lane_gap_m);
    const Vector2d d = (pts[1] - pts[0]).normalized();
    const Vector2d across(-d.y(), d.x());
    std::vector<double> off;
    for (const auto& l : lamps) {
      const Vector2d p = l.xyz.head<2>();
      if (!reach.contains(p)) continue;
      pts.push_back(p);
      off.push_back(across.dot(p));
    }
    std::sort(off.begin(), off.end());
    const auto rows = rows_of(off);
    if (!rows.empty() && rows.back().second - rows.front().first >= o.hall_min_spread_m)
      kept.push_back(std::move(pts));
  }
  for (const auto& pts : kept) halls.push_back(grown_hull(pts, o.hall_margin_m));
  return halls;
}

// Halls seen from one lane: lamps beside the drive in no corridor's band (nor in a hall found from
// lanes), at least hall_min_lamps of them each within hall_link_m (or hall_link_per_height times
// their height) of another. Such lamps are not in a row along the drive: the camera saw them off
// to its sides, under a high ceiling or in a wide room.
std::vector<graph::Polygon> halls_beside(const std::vector<Line>& lines,
                                         const std::vector<Run>& runs,
                                         const std::vector<MappedLamp>& lamps,
                                         const std::vector<graph::Polygon>& lane_halls,
                                         const TopologyOptions& o) {
  const double half = o.corridor_width_m / 2;
  std::vector<Vector2d> off, row;  // lamps in no run's band, and in one
  std::vector<double> height;
  for (const auto& l : lamps) {
    const Vector2d p = l.xyz.head<2>();
    bool in_hall = false, in_band = false;
    for (const auto& h : lane_halls) in_hall = in_hall || h.contains(p);
    for (const auto& r : runs) {
      const Line& L = lines[r.line];
      const double s = L.along(p);
      in_band = in_band || (s >= r.s0 - half && s <= r.s1 + half && L.across(p) <= half);
    }
    if (in_hall) continue;
    if (in_band) {
      row.push_back(p);
      continue;
    }
    off.push_back(p);
    height.push_back(l.xyz.z());
  }
  const auto root = components(off.size(), [&](std::size_t i, std::size_t j) {
    return (off[i] - off[j]).norm() <=
           std::max(o.hall_link_m, o.hall_link_per_height * 0.5 * (height[i] + height[j]));
  });
  // Each lamp, the drive's nearest point to it (where the robot was when it saw it), and on which
  // side of the drive it is.
  struct Cluster {
    std::vector<Vector2d> lamps, feet;
    int left = 0, right = 0;
  };
  std::map<std::size_t, Cluster> clusters;
  for (std::size_t i = 0; i < off.size(); ++i) {
    Cluster& c = clusters[root[i]];
    c.lamps.push_back(off[i]);
    std::optional<Vector2d> foot;
    Vector2d dir(1, 0);
    for (const auto& r : runs) {
      const Line& L = lines[r.line];
      const Vector2d q = L.at(std::clamp(L.along(off[i]), r.s0, r.s1));
      if (!foot || (q - off[i]).norm() < (*foot - off[i]).norm()) {
        foot = q;
        dir = L.dir;
      }
    }
    if (!foot ||
        (*foot - off[i]).norm() > std::max(o.hall_link_m, o.hall_link_per_height * height[i]))
      continue;
    c.feet.push_back(*foot);
    const Vector2d d = off[i] - *foot;
    (dir.x() * d.y() - dir.y() * d.x() > 0 ? c.left : c.right) += 1;
  }
  // A hall when the drive went through it: lamps on both sides of it, and no row of its own
  // there (at most one lamp in the drive's band within them). Lamps off to one side only (a room
  // glanced into), or on both sides of a corridor with its row of lamps (rooms on either side),
  // are no hall. The hall holds its lamps and the drive among them.
  std::vector<graph::Polygon> halls;
  for (auto& [r, c] : clusters) {
    if (static_cast<int>(c.lamps.size()) < o.hall_min_lamps || c.left == 0 || c.right == 0)
      continue;
    const graph::Polygon among = graph::convex_hull(c.lamps);
    int own_row = 0;
    for (const auto& p : row) own_row += among.size() >= 3 && among.contains(p);
    if (own_row > 1) continue;
    c.lamps.insert(c.lamps.end(), c.feet.begin(), c.feet.end());
    halls.push_back(grown_hull(c.lamps, o.hall_margin_m));
  }
  return halls;
}

// Halls whose regions overlap are one (the hull of both).
void merge_overlapping(std::vector<graph::Polygon>& halls) {
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < halls.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < halls.size() && !merged; ++j)
        if (graph::intersection_area(halls[i], halls[j]) > 0) {
          auto pts = halls[i].vertices();
          pts.insert(pts.end(), halls[j].vertices().begin(), halls[j].vertices().end());
          halls[i] = graph::convex_hull(pts);
          halls.erase(halls.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
  }
}

// The runs with what lies inside the halls cut out; the ends left at a hall say so.
std::vector<Run> cut_at_halls(const std::vector<Line>& lines, const std::vector<Run>& runs,
                              const std::vector<graph::Polygon>& halls, double min_length) {
  std::vector<Run> out;
  for (const Run& r : runs) {
    std::vector<Run> pieces = {r};
    for (std::size_t h = 0; h < halls.size(); ++h) {
      const auto [lo, hi] = inside(lines[r.line], halls[h]);
      std::vector<Run> next;
      for (const Run& p : pieces) {
        if (lo >= hi || hi <= p.s0 || lo >= p.s1) {
          next.push_back(p);
          continue;
        }
        if (lo > p.s0) next.push_back({p.line, p.s0, lo, p.hall0, static_cast<int>(h)});
        if (hi < p.s1) next.push_back({p.line, hi, p.s1, static_cast<int>(h), p.hall1});
      }
      pieces = std::move(next);
    }
    for (const Run& p : pieces)
      if (p.s1 - p.s0 >= min_length) out.push_back(p);
  }
  return out;
}

}  // namespace lampnav::mapping::drive_topology
