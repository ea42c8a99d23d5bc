#include "unmapped_rows.hpp"

#include <algorithm>
#include <cmath>

namespace lampnav::fusion::detail {

using Eigen::Vector2d;

namespace {

// The least offset across of a row beside from the mapped one: closer, a stray is the mapped
// row's own lamp seen a little off.
constexpr double kLeastOffset = 0.5;
// A stray row's lamps may be this many times the mapped row's spacing apart: a room's grid beside
// a corridor (4 m apart, beside lamps 2.25 m apart in a generated building) is no row beside.
constexpr double kSpacingRatio = 1.5;
// Sightings nearer one another than this are of one lamp.
constexpr double kSameLamp = 0.5;

double median_gap(std::vector<double> s) {
  std::sort(s.begin(), s.end());
  std::vector<double> gaps;
  for (std::size_t k = 1; k < s.size(); ++k) gaps.push_back(s[k] - s[k - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

}  // namespace

std::optional<UnmappedRow> unmapped_row_beside(const graph::TopologicalMap& map, const Pose2& pose,
                                               const std::vector<StraySighting>& strays,
                                               const UnmappedRowOptions& o) {
  const Vector2d at = pose.translation();
  // One lamp seen in several images is one: the surest sightings first, each joining the first
  // lamp within kSameLamp of it (the lamp where its first sighting put it).
  std::vector<const StraySighting*> near;
  for (const StraySighting& b : strays)
    if (b.reach <= o.reach_m && (b.at - at).norm() <= o.view_m) near.push_back(&b);
  std::stable_sort(near.begin(), near.end(), [](const StraySighting* a, const StraySighting* b) {
    return a->reach < b->reach;
  });
  std::vector<Vector2d> seen;
  for (const StraySighting* b : near)
    if (std::none_of(seen.begin(), seen.end(),
                     [&](const Vector2d& p) { return (p - b->at).norm() <= kSameLamp; }))
      seen.push_back(b->at);
  if (static_cast<int>(seen.size()) < o.min_lamps) return std::nullopt;
  std::vector<Vector2d> mapped;
  for (const graph::Lamp* l : map.lamps_within(at, o.view_m + o.max_offset_m))
    mapped.push_back(l->xyz.head<2>());
  if (mapped.size() < 3) return std::nullopt;
  std::optional<UnmappedRow> best;
  std::vector<double> along, mapped_t, mapped_s, row_s;
  // Each line through two strays: the strays on it, and a mapped row parallel to it beside.
  for (std::size_t i = 0; i < seen.size(); ++i) {
    for (std::size_t j = i + 1; j < seen.size(); ++j) {
      // (Two lamps of `seen` are more than kSameLamp apart: a line through them is defined.)
      const Vector2d u = (seen[j] - seen[i]).normalized(), n(-u.y(), u.x());
      along.clear();
      for (const Vector2d& p : seen)
        if (std::abs((p - seen[i]).dot(n)) <= o.band_m) along.push_back((p - seen[i]).dot(u));
      if (static_cast<int>(along.size()) < o.min_lamps) continue;
      std::sort(along.begin(), along.end());
      // The mapped lamps along the strays' stretch, beside their line.
      mapped_t.clear();
      mapped_s.clear();
      for (const Vector2d& p : mapped) {
        const double s = (p - seen[i]).dot(u), t = (p - seen[i]).dot(n);
        if (s < along.front() - 1 || s > along.back() + 1) continue;
        if (std::abs(t) < kLeastOffset || std::abs(t) > o.max_offset_m) continue;
        mapped_t.push_back(t);
        mapped_s.push_back(s);
      }
      for (std::size_t a = 0; a < mapped_t.size(); ++a) {
        row_s.clear();
        double t_sum = 0;
        for (std::size_t b = 0; b < mapped_t.size(); ++b)
          if (std::abs(mapped_t[b] - mapped_t[a]) <= o.band_m) {
            row_s.push_back(mapped_s[b]);
            t_sum += mapped_t[b];
          }
        if (row_s.size() < 3) continue;
        // Each offset is within [kLeastOffset, max_offset_m], all on one side: so is their mean.
        const double offset = std::abs(t_sum / static_cast<double>(row_s.size()));
        // The longest stretch of strays no further apart than the mapped row's spacing allows.
        const double gap_max = kSpacingRatio * median_gap(row_s);
        std::size_t first = 0;
        for (std::size_t k = 1; k <= along.size(); ++k) {
          if (k < along.size() && along[k] - along[k - 1] <= gap_max) continue;
          const int lamps = static_cast<int>(k - first);
          if (lamps >= o.min_lamps && (!best || lamps > best->lamps))
            best = UnmappedRow{lamps, offset, along[k - 1] - along[first]};
          first = k;
        }
      }
    }
  }
  // A row among many strays is no sign of a row the map lacks: the pose is wrong, and its view
  // unexplained (a place after a carry, whose 18 strays in the museum held a row of 4).
  if (best && 2 * best->lamps < static_cast<int>(seen.size())) return std::nullopt;
  return best;
}

}  // namespace lampnav::fusion::detail
