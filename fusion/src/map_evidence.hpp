#pragma once
// What the map's own errors may cost a hypothesis. A map is not the building: a lamp in it may be
// out, a few centimetres off, or missing from it. Each such error is the same in every frame, so
// a frame's evidence about it is not new: counted anew in each, one error of the map decides
// between look-alike places (a lamp out made its twin place a thousand times likelier within a
// second; lamps 3 cm off made twins 20 m apart certain, docs/hypotheses.md). The ledger records
// what each map lamp, and each spot where lamps were seen that the map lacks, has cost a
// hypothesis so far, and charges none of them past a bound over all its frames together (a
// lamp's misfit: the worst any frame found).
// Private to hypothesis_set.cpp.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// Charges `cost` (at least 0) to an account that holds `spent` and may hold at most `most`:
// returns what was charged.
inline double charge_account(double& spent, double cost, double most) {
  const double c = std::clamp(most - spent, 0.0, std::max(0.0, cost));
  spent += c;
  return c;
}

using LampLedger = decltype(MapErrorCosts::lamps);
using StrayLedger = decltype(MapErrorCosts::strays);

inline double& account_of(LampLedger& ledger, const graph::Lamp* lamp) {
  auto it =
      std::find_if(ledger.begin(), ledger.end(), [&](const auto& a) { return a.first == lamp; });
  if (it == ledger.end()) it = ledger.insert(ledger.end(), {lamp, 0.0});
  return it->second;
}

// Charges the lamps a frame expected and did not see, `each` a lamp, none past `most` in all.
inline double charge_absences(LampLedger& ledger, const std::vector<const graph::Lamp*>& missed,
                              double each, double most) {
  double cost = 0;
  for (const graph::Lamp* l : missed) cost += charge_account(account_of(ledger, l), each, most);
  return cost;
}

// A map lamp's misfit: what a frame's directions to it, or its sighting outside the labeller's
// gate, say against it (-2 ln L). A lamp a few centimetres off misfits alike in every frame that
// sees it, so it costs the worst any frame said, not their sum, and at most `most`: under such a
// map the place whose lamps happen to lie nearer the true ones fits better in every frame, and
// that says nothing of where the robot is. Returns what the frame adds.
inline double charge_misfit(LampLedger& ledger, const graph::Lamp* lamp, double share,
                            double most) {
  double& worst = account_of(ledger, lamp);
  const double c = std::clamp(share, 0.0, most) - worst;
  if (!(c > 0)) return 0.0;
  worst += c;
  return c;
}

// A lamp seen at `at` (within `radius`, how well the sighting places it) where the map has none,
// charged `each`, no spot past `most` in all.
inline double charge_stray(StrayLedger& ledger, const Eigen::Vector2d& at, double radius,
                           double each, double most) {
  auto it = std::find_if(ledger.begin(), ledger.end(), [&](const MapErrorCosts::Stray& s) {
    return (s.at - at).squaredNorm() < std::pow(std::max(s.radius, radius), 2);
  });
  if (it == ledger.end()) it = ledger.insert(ledger.end(), MapErrorCosts::Stray{at, radius, 0.0});
  return charge_account(it->spent, each, most);
}

// A fit's misfit (-2 ln L past what the map's errors explain) charged to the lamps it was
// measured from, in equal shares, each as charge_misfit().
inline double charge_fit(LampLedger& ledger, const std::vector<const graph::Lamp*>& lamps,
                         double cost, double most) {
  if (lamps.empty() || !(cost > 0)) return 0.0;
  const double share = cost / static_cast<double>(lamps.size());
  double charged = 0;
  for (const graph::Lamp* l : lamps) charged += charge_misfit(ledger, l, share, most);
  return charged;
}

// A score that charged `count` things `each` (-2 ln L), as a ledger would charge them on an empty
// account bounded by `most`.
inline double with_each_bounded(double score, int count, double each, double most) {
  return score - (each - std::min(each, most)) * count;
}

}  // namespace lampnav::fusion::detail
