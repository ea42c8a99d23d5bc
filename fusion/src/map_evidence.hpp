#pragma once
// What the absence of map lamps costs a hypothesis when a lamp may be out: each frame's miss
// charged as usual, but no lamp's absences more than a bound over all the hypothesis's frames
// together (HypothesisSetOptions::lamp_out_cost). Private to hypothesis_set.cpp.

#include <algorithm>
#include <utility>
#include <vector>

#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// What each map lamp's absence has cost a hypothesis so far (Hypothesis::absences).
using AbsenceLedger = std::vector<std::pair<const graph::Lamp*, double>>;

// Charges the lamps a frame expected and did not see, `each` a lamp, none past `most` in all:
// returns the cost and records it in the ledger.
inline double charge_absences(AbsenceLedger& ledger, const std::vector<const graph::Lamp*>& missed,
                              double each, double most) {
  double cost = 0;
  for (const graph::Lamp* l : missed) {
    auto it =
        std::find_if(ledger.begin(), ledger.end(), [&](const auto& a) { return a.first == l; });
    if (it == ledger.end()) it = ledger.insert(ledger.end(), {l, 0.0});
    const double c = std::clamp(most - it->second, 0.0, each);
    it->second += c;
    cost += c;
  }
  return cost;
}

// A score that charged `missing` lamps `each` (-2 ln L), as charge_absences() would on an empty
// ledger.
inline double with_absences_bounded(double score, int missing, double each, double most) {
  return score - (each - std::min(each, most)) * missing;
}

}  // namespace lampnav::fusion::detail
