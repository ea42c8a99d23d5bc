#include "lampnav/mapping/topology.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "halls.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "seen_ways.hpp"

namespace lampnav::mapping {

using Eigen::Vector2d;

void TopologyOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"topology options", "", field}, what);
  };
  check(corridor_width_m > 0.3 && corridor_width_m < 20, "corridor_width_m", "must be 0.3 to 20 m");
  check(simplify_m > 0, "simplify_m", "must be positive");
  check(min_stretch_m > 0, "min_stretch_m", "must be positive");
  check(turn_m >= 0, "turn_m", "must not be negative");
  check(same_line_m > 0, "same_line_m", "must be positive");
  check(parallel_deg > 0 && parallel_deg < 45, "parallel_deg", "must be 0 to 45 degrees");
  check(gap_m >= 0, "gap_m", "must not be negative");
  check(place_m > 0, "place_m", "must be positive");
  check(hall_lane_gap_m == 0 || hall_lane_gap_m > same_line_m, "hall_lane_gap_m",
        "must be 0 (no halls) or more than same_line_m");
  check(hall_min_overlap_m > 0, "hall_min_overlap_m", "must be positive");
  check(hall_min_spread_m >= 0, "hall_min_spread_m", "must not be negative");
  check(hall_margin_m >= 0 && hall_margin_m < 10, "hall_margin_m", "must be 0 to 10 m");
  check(hall_min_lamps >= 0, "hall_min_lamps", "must not be negative");
  check(hall_link_m > 0, "hall_link_m", "must be positive");
  check(hall_link_per_height >= 0, "hall_link_per_height", "must not be negative");
  check(way_min_lamps >= 0 && way_min_lamps != 1, "way_min_lamps",
        "must be 0 (no ways seen) or at least 2");
  check(way_across_m > 0, "way_across_m", "must be positive");
  check(way_gap_m > 0, "way_gap_m", "must be positive");
  check(way_first_lamp_m > 0, "way_first_lamp_m", "must be positive");
  check(way_beside_m >= 0, "way_beside_m", "must not be negative");
  check(way_clear_m >= 0, "way_clear_m", "must not be negative");
  check(way_min_angle_deg > 0 && way_min_angle_deg <= 90, "way_min_angle_deg",
        "must be 0 to 90 degrees");
  check(rows_reach_m >= 0, "rows_reach_m", "must not be negative");
  check(row_beside_m >= 0, "row_beside_m", "must not be negative");
}

namespace {

// A direction in the map's frame as users read it: whole degrees, 0 to 359.
int heading_deg(const Vector2d& v) {
  const long deg = std::lround(std::atan2(v.y(), v.x()) * 180 / M_PI);
  return static_cast<int>((deg % 360 + 360) % 360);
}

using namespace drive_topology;

struct Place {
  Vector2d point = Vector2d::Zero();
  int members = 0;
  std::vector<Vector2d> ways;
  std::vector<Vector2d> seen;  // of the ways, those seen and not driven
  graph::Place kind = graph::Place::junction;
  int node = -1;
  int hall = -1;  // a hall: its index, its region in `region`
  graph::Polygon region;
  std::vector<int> beside;  // the halls next to it
};

// Douglas-Peucker: indices of the points kept.
void simplify(const std::vector<Vector2d>& p, std::size_t a, std::size_t b, double tol,
              std::vector<std::size_t>& keep) {
  if (b <= a + 1) return;
  const Vector2d d = p[b] - p[a];
  const double len = d.norm();
  double worst = -1;
  std::size_t at = a;
  for (std::size_t i = a + 1; i < b; ++i) {
    const Vector2d e = p[i] - p[a];
    const double dist = len > 1e-9 ? std::abs(d.x() * e.y() - d.y() * e.x()) / len : e.norm();
    if (dist > worst) {
      worst = dist;
      at = i;
    }
  }
  if (worst > tol) {
    simplify(p, a, at, tol, keep);
    keep.push_back(at);
    simplify(p, at, b, tol, keep);
  }
}

// Where the line through `p` along `u` meets the line through `q` along `w` (`cross`, u x w, not
// 0; u and w need not be unit vectors).
Vector2d meet_of_lines(const Vector2d& p, const Vector2d& u, const Vector2d& q, const Vector2d& w,
                       double cross) {
  const Vector2d d = q - p;
  return p + u * ((d.x() * w.y() - d.y() * w.x()) / cross);
}

// The simplified drive's vertices, where a turn left short stretches beside its corner (the robot
// approaching it askew, settling onto the new corridor's line, or cutting the corner:
// TopologyOptions::turn_m): the vertices between the last long stretch before and the first after
// are moved to where those two stretches' lines meet, which leaves the short ones no length. Not
// for stretches between parallel ones (a U-turn, a hall's turn from one lane to the next) nor where
// the lines meet far off (a shallow bend).
void cut_corners_met(std::vector<Vector2d>& v, double turn_m, double parallel) {
  const double kSettleCos = std::cos(20 * M_PI / 180);
  auto length = [&](std::size_t k) { return (v[k + 1] - v[k]).norm(); };  // stretch k
  // Each short stretch runs nearly along the line before or the line after (within 20 degrees):
  // a stretch across the corner at a wider angle is a way of its own (through a door, a diagonal
  // hall), kept.
  auto along = [&](std::size_t k, const Vector2d& line) {
    return std::abs((v[k + 1] - v[k]).normalized().dot(line.normalized())) > kSettleCos;
  };
  for (std::size_t i = 1; i + 2 < v.size(); ++i) {
    if (length(i - 1) < turn_m) continue;  // stretch i - 1 is the long one before
    std::size_t j = i;                     // vertices i..j lie between the two long stretches
    while (j + 1 < v.size() && length(j) < turn_m &&
           (along(j, v[i] - v[i - 1]) || (j + 2 < v.size() && along(j, v[j + 2] - v[j + 1]))))
      ++j;
    if (j == i || j + 1 >= v.size() || length(j) < turn_m) continue;
    const Vector2d before = v[i] - v[i - 1], after = v[j + 1] - v[j];
    const double cross = before.x() * after.y() - before.y() * after.x();
    if (std::abs(cross) <= parallel * before.norm() * after.norm()) continue;
    const Vector2d meet = meet_of_lines(v[i - 1], before, v[j], after, cross);
    if ((meet - v[i]).norm() > turn_m || (meet - v[j]).norm() > turn_m) continue;
    for (std::size_t k = i; k <= j; ++k) v[k] = meet;
    i = j;
  }
}

Vector2d canonical(Vector2d d) {
  d.normalize();
  if (d.x() < -1e-9 || (std::abs(d.x()) <= 1e-9 && d.y() < 0)) d = -d;
  return d;
}

graph::Polygon rectangle(const Vector2d& a, const Vector2d& b, double width) {
  const Vector2d d = (b - a).normalized();
  const Vector2d n(-d.y() * width / 2, d.x() * width / 2);
  return graph::Polygon({a - n, b - n, b + n, a + n});
}

}  // namespace

graph::TopologicalMap build_topology(const MappingResult& mapped, const TopologyOptions& o,
                                     const std::vector<PlaceName>& names, TopologyReport* report,
                                     const std::vector<Vector2d>& seen) {
  o.validate();
  TopologyReport rep;
  std::vector<Vector2d> pts;
  for (const auto& k : mapped.keyframes) pts.push_back(k.pose.translation());
  graph::TopologicalMap map("built");
  if (pts.size() < 2) {
    rep.notes.push_back("the drive has fewer than two keyframes: no places");
    if (report) *report = rep;
    return map;
  }

  // 1. Straight stretches of the drive, grouped into lines.
  std::vector<std::size_t> keep = {0};
  simplify(pts, 0, pts.size() - 1, o.simplify_m, keep);
  keep.push_back(pts.size() - 1);
  std::sort(keep.begin(), keep.end());
  const double parallel = std::sin(o.parallel_deg * M_PI / 180);
  std::vector<Vector2d> corners;
  for (const std::size_t k : keep) corners.push_back(pts[k]);
  cut_corners_met(corners, o.turn_m, parallel);
  // The longest stretches first: a line is set by the long stretch of a corridor, and a short
  // one beside it (the robot settling onto the corridor after a turn, a few degrees off its
  // axis) joins it, where taken in the drive's order it would set a line of its own that the
  // long stretch, diverging from it, could not join; the bend between them then is no place,
  // and the corridor, with no place on its line at one end, would be left out with its lamps.
  std::vector<std::size_t> by_length;
  for (std::size_t i = 1; i < corners.size(); ++i) by_length.push_back(i);
  std::stable_sort(by_length.begin(), by_length.end(), [&](std::size_t i, std::size_t j) {
    return (corners[i] - corners[i - 1]).norm() > (corners[j] - corners[j - 1]).norm();
  });
  std::vector<Line> lines;
  for (const std::size_t i : by_length) {
    const Vector2d a = corners[i - 1], b = corners[i];
    if ((b - a).norm() < o.min_stretch_m) continue;
    const Vector2d d = canonical(b - a);
    int found = -1;
    for (std::size_t l = 0; l < lines.size(); ++l) {
      const Vector2d& ld = lines[l].dir;
      if (std::abs(ld.x() * d.y() - ld.y() * d.x()) > parallel) continue;
      if (lines[l].across(a) < o.same_line_m && lines[l].across(b) < o.same_line_m) {
        found = static_cast<int>(l);
        break;
      }
    }
    if (found < 0) {
      lines.push_back({a, d, {}});
      found = static_cast<int>(lines.size()) - 1;
    }
    Line& L = lines[found];
    const double sa = L.along(a), sb = L.along(b);
    L.intervals.emplace_back(std::min(sa, sb), std::max(sa, sb));
  }
  // A wide corridor driven up one of its rows and back along the other is one corridor, as wide
  // as its rows and 0.4 m beyond each (the regions' width, when more than the option's).
  constexpr double kBeyondRows = 0.4;
  const std::vector<double> joined = join_lanes_under_two_rows(lines, mapped.lamps, o);
  rep.lanes_joined = joined.size();
  const double widest = joined.empty() ? 0.0 : *std::max_element(joined.begin(), joined.end());
  const double w = std::max(o.corridor_width_m, widest + 2 * kBeyondRows);
  if (w > o.corridor_width_m) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "corridors are %.1f m wide, not %.1f: the rows of a corridor driven under "
                  "each are %.1f m apart",
                  w, o.corridor_width_m, widest);
    rep.notes.push_back(buf);
  }
  const double near = std::max(o.place_m, w);
  TopologyOptions wide = o;  // for the steps that take the corridors' width from the options
  wide.corridor_width_m = w;
  std::vector<Run> runs;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    auto iv = lines[l].intervals;
    std::sort(iv.begin(), iv.end());
    for (const auto& [s0, s1] : iv) {
      if (!runs.empty() && runs.back().line == static_cast<int>(l) &&
          s0 <= runs.back().s1 + o.gap_m) {
        runs.back().s1 = std::max(runs.back().s1, s1);
      } else {
        runs.push_back({static_cast<int>(l), s0, s1});
      }
    }
  }

  // 1b. Halls, and the runs with their stretches through halls cut out.
  std::vector<graph::Polygon> halls = halls_from_lanes(lines, runs, mapped.lamps, o);
  if (o.hall_min_lamps > 0) {
    const auto beside = halls_beside(lines, runs, mapped.lamps, halls, wide);
    halls.insert(halls.end(), beside.begin(), beside.end());
  }
  merge_overlapping(halls);
  if (!halls.empty())
    rep.notes.push_back(std::to_string(halls.size()) + (halls.size() == 1 ? " hall" : " halls") +
                        " (lamps not in rows along the drive)");
  runs = cut_at_halls(lines, runs, halls, o.min_stretch_m);

  // 2. Places: where runs of two lines meet, and where a run ends with nothing there.
  std::vector<Place> places;
  auto add_place = [&](const Vector2d& p) {
    for (auto& q : places) {
      if ((q.point - p).norm() < near) {
        q.point = (q.point * q.members + p) / (q.members + 1);
        ++q.members;
        return;
      }
    }
    Place q;
    q.point = p;
    q.members = 1;
    places.push_back(q);
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    for (std::size_t j = i + 1; j < runs.size(); ++j) {
      const Line &A = lines[runs[i].line], &B = lines[runs[j].line];
      const double cross = A.dir.x() * B.dir.y() - A.dir.y() * B.dir.x();
      if (std::abs(cross) <= parallel) continue;
      const Vector2d p = meet_of_lines(A.origin, A.dir, B.origin, B.dir, cross);
      const double s = A.along(p);
      const double t = B.along(p);
      if (s < runs[i].s0 - o.place_m || s > runs[i].s1 + o.place_m) continue;
      if (t < runs[j].s0 - o.place_m || t > runs[j].s1 + o.place_m) continue;
      add_place(p);
    }
  }
  for (const auto& r : runs) {
    if (r.hall0 < 0) add_place(lines[r.line].at(r.s0));
    if (r.hall1 < 0) add_place(lines[r.line].at(r.s1));
  }
  // 2b. Ways out not driven, seen: where one meets a run is a place.
  const std::vector<RowBeside> unmapped_rows = rows_beside(lines, runs, mapped.lamps, seen, o);
  const std::vector<SeenWay> seen_ways =
      ways_not_driven(lines, runs, mapped.lamps, seen, unmapped_rows, wide);
  for (const SeenWay& x : seen_ways) add_place(x.at);
  // Ways out of each place: the runs that go on from it by more than a place's size.
  // Where a point lies along a run (the distance along its line), if the run passes it.
  auto along_run = [&](const Run& r, const Vector2d& p) -> std::optional<double> {
    const Line& L = lines[r.line];
    const double s = L.along(p);
    if (L.across(p) < o.same_line_m + 0.5 && s >= r.s0 - near && s <= r.s1 + near) return s;
    return std::nullopt;
  };
  auto runs_through = [&](const Place& q) {
    std::vector<std::pair<const Run*, double>> out;
    for (const auto& r : runs)
      if (const auto s = along_run(r, q.point)) out.emplace_back(&r, *s);
    return out;
  };
  std::vector<Place> kept;
  for (auto& q : places) {
    bool in_hall = false;
    for (const auto& h : halls) in_hall = in_hall || h.contains(q.point);
    if (in_hall) continue;
    auto add_way = [&](const Vector2d& way) {
      bool known = false;
      for (const auto& v : q.ways) known = known || v.dot(way) > std::cos(20 * M_PI / 180);
      if (!known) q.ways.push_back(way);
      return !known;
    };
    for (const auto& [r, s] : runs_through(q)) {
      const Vector2d d = lines[r->line].dir;
      for (const Vector2d& way : {Vector2d(d), Vector2d(-d)}) {
        const bool ahead = way.dot(d) > 0;
        const bool goes_on =
            ahead ? r->s1 - s > near || r->hall1 >= 0 : s - r->s0 > near || r->hall0 >= 0;
        if (goes_on) add_way(way);
      }
    }
    for (std::size_t h = 0; h < halls.size(); ++h) {
      const Vector2d to = halls[h].nearest_on_boundary(q.point) - q.point;
      if (to.norm() > near) continue;
      if (to.norm() > 1e-6) add_way(to.normalized());  // into the hall next to it
      q.beside.push_back(static_cast<int>(h));
    }
    // Ways seen and not driven count where they change the place's kind: a junction the drive
    // went three ways out of stays as it is.
    const std::size_t driven = q.ways.size();
    for (const SeenWay& s : seen_ways)
      if (driven < 3 && (s.at - q.point).norm() < near && add_way(s.way)) q.seen.push_back(s.way);
    const std::size_t n = q.ways.size();
    if (n == 2 && q.ways[0].dot(q.ways[1]) < -std::cos(20 * M_PI / 180)) continue;  // straight on
    q.kind = n <= 1 ? graph::Place::end : n == 2 ? graph::Place::corner : graph::Place::junction;
    kept.push_back(q);
  }
  places = std::move(kept);
  // The halls are places too, after the others.
  const int first_hall = static_cast<int>(places.size());
  for (std::size_t h = 0; h < halls.size(); ++h) {
    Place q;
    q.kind = graph::Place::hall;
    q.hall = static_cast<int>(h);
    q.region = halls[h];
    q.point = halls[h].centroid();
    places.push_back(q);
  }

  // When the drive first came near a point: places and corridors are numbered in that order.
  auto first_reached = [&](const Vector2d& p) {
    for (std::size_t k = 0; k < pts.size(); ++k)
      if ((pts[k] - p).norm() < near) return k;
    return pts.size();
  };
  auto first_inside = [&](const graph::Polygon& region) {
    for (std::size_t k = 0; k < pts.size(); ++k)
      if (region.contains(pts[k])) return k;
    return pts.size();
  };

  // 3. Corridors: the pieces of each run between consecutive places on it.
  struct Corridor {
    Vector2d a, b;  // axis
    int from, to;   // places
  };
  std::vector<Corridor> corridors;
  std::set<std::pair<int, int>> links;  // places linked directly (a place and a hall beside it)
  for (int i = 0; i < first_hall; ++i)
    for (const int h : places[i].beside) links.insert({i, first_hall + h});
  for (const auto& r : runs) {
    const Line& L = lines[r.line];
    std::vector<std::pair<double, int>> on;
    for (int i = 0; i < first_hall; ++i)
      if (const auto s = along_run(r, places[i].point)) on.emplace_back(*s, i);
    if (r.hall0 >= 0) on.emplace_back(r.s0, first_hall + r.hall0);
    if (r.hall1 >= 0) on.emplace_back(r.s1, first_hall + r.hall1);
    std::sort(on.begin(), on.end());
    for (std::size_t k = 1; k < on.size(); ++k) {
      const auto [s0, p0] = on[k - 1];
      const auto [s1, p1] = on[k];
      if (p0 == p1) continue;
      // Along the line itself, from one place's square to the next one's (a hall's edge).
      const double a = s0 + (places[p0].hall < 0 ? w / 2 : 0);
      const double b = s1 - (places[p1].hall < 0 ? w / 2 : 0);
      if (b - a < 0.5) {
        if (places[p0].hall >= 0 || places[p1].hall >= 0) links.insert({p0, p1});
        continue;
      }
      if (s1 - s0 < w + 0.5) continue;
      corridors.push_back({L.at(a), L.at(b), p0, p1});
    }
  }

  // 4. Nodes, in the order the drive reached them, with names and regions.
  struct Pending {
    std::size_t reached;
    bool corridor;
    int index;
  };
  std::vector<Pending> order;
  for (std::size_t i = 0; i < places.size(); ++i)
    order.push_back(
        {places[i].hall >= 0 ? first_inside(places[i].region) : first_reached(places[i].point),
         false, static_cast<int>(i)});
  for (std::size_t i = 0; i < corridors.size(); ++i)
    order.push_back(
        {first_reached(0.5 * (corridors[i].a + corridors[i].b)), true, static_cast<int>(i)});
  std::stable_sort(order.begin(), order.end(),
                   [](const Pending& x, const Pending& y) { return x.reached < y.reached; });
  std::map<char, int> counters;
  std::vector<graph::Node> nodes;
  std::vector<int> corridor_node(corridors.size(), -1);
  for (const auto& p : order) {
    graph::Node n;
    n.id = NodeId(static_cast<std::int64_t>(nodes.size()) + 1);
    char letter;
    if (p.corridor) {
      const Corridor& c = corridors[p.index];
      n.place = graph::Place::corridor;
      n.axis = graph::Axis{c.a, c.b};
      n.width = w;
      n.point = 0.5 * (c.a + c.b);
      n.region = rectangle(c.a, c.b, w);
      letter = 'C';
      corridor_node[p.index] = static_cast<int>(nodes.size());
    } else if (places[p.index].hall >= 0) {
      Place& q = places[p.index];
      n.place = graph::Place::hall;
      n.region = q.region;
      n.point = q.point;
      letter = 'H';
      q.node = static_cast<int>(nodes.size());
    } else {
      Place& q = places[p.index];
      n.place = q.kind;
      n.point = q.point;
      // A square across the corridors that meet here (a hair smaller, so that estimates a
      // tenth of a degree apart do not make neighbours overlap).
      const Vector2d d = q.ways.empty() ? Vector2d(1, 0) : q.ways.front();
      const double side = w - 0.02;
      n.region = rectangle(q.point - d * side / 2, q.point + d * side / 2, side);
      letter = q.kind == graph::Place::end ? 'E' : q.kind == graph::Place::corner ? 'K' : 'J';
      q.node = static_cast<int>(nodes.size());
    }
    n.name = std::string(1, letter) + std::to_string(++counters[letter]);
    for (const auto& nm : names)
      if (n.region.contains(nm.at)) n.name = nm.name;
    nodes.push_back(std::move(n));
  }

  // Regions must not overlap (map-format.md): where the drive's geometry makes two meet at an
  // angle, the corridor gives way (shortened at that end), or the later of two places shrinks; a
  // corridor shorter than half a metre, or a place smaller than that, is left out.
  std::vector<bool> dropped(nodes.size(), false);
  const double allowed = 0.5 * graph::kRegionOverlapTolerance;
  auto overlap = [&](std::size_t a, std::size_t b) {
    const auto &ra = nodes[a].region, &rb = nodes[b].region;
    if (!ra.bounds().intersects(rb.bounds())) return 0.0;
    return graph::intersection_area(ra, rb);
  };
  // One step of giving way to `other`: a corridor shortened by 10 cm at its end nearer the other,
  // a place shrunk by a tenth; false when what is left is too small to keep.
  auto give_way = [&](graph::Node& n, const graph::Node& other) {
    if (n.axis) {
      graph::Axis& ax = *n.axis;
      const Vector2d c = other.region.centroid();
      const Vector2d d = ax.direction() * 0.1;
      if ((ax.first - c).norm() < (ax.second - c).norm())
        ax.first += d;
      else
        ax.second -= d;
      if (ax.length() < 0.5) return false;
      n.region = rectangle(ax.first, ax.second, w);
      n.point = 0.5 * (ax.first + ax.second);
      return true;
    }
    if (n.place == graph::Place::hall) {
      // Cut along the other's edge that leaves the most of the hall's lamps, then of its area
      // (both regions are convex).
      std::vector<Vector2d> v = other.region.vertices();
      if (other.region.signed_area() < 0) std::reverse(v.begin(), v.end());
      graph::Polygon best;
      std::pair<int, double> best_score(-1, 0.0);
      for (std::size_t i = 0; i < v.size(); ++i) {
        graph::Polygon cut = graph::clip_left_of(n.region, v[(i + 1) % v.size()], v[i]);
        if (cut.size() < 3) continue;
        int held = 0;
        for (const auto& l : mapped.lamps) held += cut.contains(l.xyz.head<2>(), 1e-6);
        const std::pair<int, double> score(held, cut.area());
        if (score > best_score) {
          best_score = score;
          best = std::move(cut);
        }
      }
      if (best.size() < 3 || best.area() < 0.25) return false;
      n.region = best;
      n.point = best.centroid();
      return true;
    }
    std::vector<Vector2d> smaller;
    for (const auto& p : n.region.vertices()) smaller.push_back(n.point + 0.9 * (p - n.point));
    n.region = graph::Polygon(smaller);
    return (smaller[0] - smaller[1]).norm() >= 0.5;
  };
  for (std::size_t b = 0; b < nodes.size(); ++b)
    for (std::size_t a = 0; a < b; ++a) {
      if (dropped[a] || dropped[b]) continue;
      for (int step = 0; step < 40 && overlap(a, b) > allowed; ++step) {
        // The one to give way: a hall (cut along the other's edge), then a corridor
        // (shortened), else the later one.
        const auto hall = [&](std::size_t i) { return nodes[i].place == graph::Place::hall; };
        const std::size_t g = hall(b) ? b : hall(a) ? a : nodes[b].axis ? b : nodes[a].axis ? a : b;
        if (!give_way(nodes[g], nodes[g == b ? a : b])) {
          dropped[g] = true;
          break;
        }
      }
    }
  std::size_t left_out = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) left_out += dropped[i];
  if (left_out)
    rep.notes.push_back(std::to_string(left_out) +
                        (left_out == 1
                             ? " place was left out: its region would overlap others"
                             : " places were left out: their regions would overlap others") +
                        " (the drive met them at an angle)");

  // A drive all in one hall has no way between places, which a map must have (Nav2 loads no
  // graph without an edge): the hall is cut in two across its longest extent, the halves linked.
  std::vector<std::pair<std::size_t, std::size_t>> node_links;
  std::vector<std::size_t> live;
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!dropped[i]) live.push_back(i);
  if (live.size() == 1 && nodes[live[0]].place == graph::Place::hall &&
      nodes[live[0]].region.area() >= 1.0) {
    const graph::Node whole = nodes[live[0]];
    const auto& v = whole.region.vertices();
    Vector2d d(1, 0);
    double longest = 0;
    for (const auto& p : v)
      for (const auto& q : v)
        if ((q - p).norm() > longest) {
          longest = (q - p).norm();
          d = (q - p) / longest;
        }
    const Vector2d c = whole.region.centroid(), n(-d.y(), d.x());
    graph::Node first = whole, second = whole;
    first.region = graph::clip_left_of(whole.region, c + n, c);
    second.region = graph::clip_left_of(whole.region, c, c + n);
    first.point = first.region.centroid();
    second.point = second.region.centroid();
    second.id = NodeId(static_cast<std::int64_t>(nodes.size()) + 1);
    second.name = "H" + std::to_string(++counters['H']);
    for (const auto& nm : names)
      if (second.region.contains(nm.at)) second.name = nm.name;
    nodes[live[0]] = first;
    nodes.push_back(second);
    dropped.push_back(false);
    node_links.emplace_back(live[0], nodes.size() - 1);
    rep.notes.push_back(
        "the drive was all in one hall: it is cut in two halves across its length, " + first.name +
        " and " + second.name +
        ", so that the map has a way between places (merge or rename them by hand)");
  }

  // The ways out counted but not driven, for the user: they are not in the map.
  for (const Place& q : places) {
    if (q.seen.empty() || q.node < 0 || dropped[q.node]) continue;
    rep.ways_seen += q.seen.size();
    std::string headings;
    for (const Vector2d& way : q.seen)
      headings += (headings.empty() ? "" : " and ") + std::to_string(heading_deg(way));
    rep.notes.push_back(nodes[q.node].name + " is a " + graph::to_string(q.kind) + " by " +
                        (q.seen.size() == 1 ? "a way" : "ways") +
                        " out the omni camera saw and the drive did not take (heading " + headings +
                        " degrees in the map's frame): drive " +
                        (q.seen.size() == 1 ? "it" : "them") + " to map " +
                        (q.seen.size() == 1 ? "its corridor" : "their corridors"));
  }

  // Rows beside the driven ones (a wide corridor's other row), seen and not mapped.
  for (const RowBeside& b : unmapped_rows) {
    std::string where = "the drive";
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!dropped[i] && nodes[i].region.contains(b.middle, 0.5)) where = nodes[i].name;
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "the omni camera saw another row of lamps %.1f m beside %s, along %.0f m of it "
                  "(towards heading %d degrees in the map's frame), that the map does not hold: "
                  "the ceiling camera saw them only at its border; drive under that row too (on "
                  "this map, a robot there not told its start stays unsure which row it is "
                  "under: docs/mapping.md, \"Corridors of two rows\")",
                  b.apart_m, where.c_str(), b.s1 - b.s0, heading_deg(b.towards));
    rep.notes.push_back(buf);
    ++rep.rows_beside;
  }

  // 5. Lamps into the place whose region holds them, in walking order.
  std::vector<std::vector<const MappedLamp*>> held(nodes.size());
  for (const auto& l : mapped.lamps) {
    int at = -1;
    for (std::size_t i = 0; i < nodes.size() && at < 0; ++i)
      if (!dropped[i] && nodes[i].region.contains(l.xyz.head<2>(), 1e-6)) at = static_cast<int>(i);
    if (at < 0) {
      ++rep.lamps_outside;
      continue;
    }
    held[at].push_back(&l);
    ++rep.lamps_placed;
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    graph::Node& n = nodes[i];
    auto& ls = held[i];
    if (n.axis) {
      std::sort(ls.begin(), ls.end(), [&](const MappedLamp* x, const MappedLamp* y) {
        return n.axis->along(x->xyz.head<2>()) < n.axis->along(y->xyz.head<2>());
      });
    }
    for (const MappedLamp* l : ls) {
      n.lamps.push_back(l->as_map_lamp(LampId(n.name + "-L" + std::to_string(n.lamps.size() + 1))));
    }
  }
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!dropped[i]) map.add_node(nodes[i]);

  // 6. Edges: each corridor to the places at its ends, and each hall to the places beside it,
  // both ways.
  std::int64_t next_edge = 1000;
  auto link = [&](const graph::Node& a, const graph::Node& b) {
    for (const auto& [s, e] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
      graph::Edge edge;
      edge.id = EdgeId(next_edge++);
      edge.start = s->id;
      edge.end = e->id;
      edge.geometry = {{s->point, e->point}};
      edge.cost = (e->point - s->point).norm();
      map.add_edge(edge);
    }
  };
  for (std::size_t i = 0; i < corridors.size(); ++i) {
    if (dropped[corridor_node[i]]) continue;
    for (const int pl : {corridors[i].from, corridors[i].to})
      if (!dropped[places[pl].node]) link(nodes[corridor_node[i]], nodes[places[pl].node]);
  }
  for (const auto& [p, q] : links)
    if (!dropped[places[p].node] && !dropped[places[q].node])
      link(nodes[places[p].node], nodes[places[q].node]);
  for (const auto& [a, b] : node_links) link(nodes[a], nodes[b]);
  if (rep.lamps_outside)
    rep.notes.push_back(std::to_string(rep.lamps_outside) +
                        (rep.lamps_outside == 1 ? " lamp lies" : " lamps lie") +
                        " in no corridor, place or hall the drive went through "
                        "(rooms, halls seen from one lane): left out");
  if (report) *report = rep;
  return map;
}

}  // namespace lampnav::mapping
