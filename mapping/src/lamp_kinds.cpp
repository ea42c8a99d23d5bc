#include "lampnav/mapping/lamp_kinds.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "lampnav/core/error.hpp"
#include "median.hpp"

namespace lampnav::mapping {

void LampKindOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"lamp kind options", "", field}, what);
  };
  check(split_log_gap > 0 && split_log_gap < 2, "split_log_gap", "must be above 0 and below 2");
  check(min_sightings >= 1, "min_sightings", "must be at least 1");
  check(min_share >= 0 && min_share < 1, "min_share", "must be from 0 to below 1");
  check(min_distance > 0 && min_distance <= 1, "min_distance", "must be above 0 and at most 1");
  check(max_distance >= 1, "max_distance", "must be at least 1");
}

namespace {

bool is_long(double length, double width) { return length > kLongLamp * width; }

// `group` split where neighbours sorted by `key` lie more than `gap` apart.
template <class Key>
std::vector<std::vector<std::size_t>> split(std::vector<std::size_t> group, Key key, double gap) {
  std::sort(group.begin(), group.end(),
            [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  std::vector<std::vector<std::size_t>> out;
  for (std::size_t k = 0; k < group.size(); ++k) {
    if (k == 0 || key(group[k]) - key(group[k - 1]) > gap) out.emplace_back();
    out.back().push_back(group[k]);
  }
  return out;
}

}  // namespace

std::vector<vision::LampShapePrior> lamp_kinds(const std::vector<LampLook>& looks,
                                               const LampKindOptions& o) {
  o.validate();
  std::vector<std::size_t> shapes[2];  // long, round
  for (std::size_t i = 0; i < looks.size(); ++i)
    shapes[is_long(looks[i].length, looks[i].width) ? 0 : 1].push_back(i);
  auto log_length = [&](std::size_t i) { return std::log(looks[i].length); };
  auto log_width = [&](std::size_t i) { return std::log(looks[i].width); };
  struct Group {
    bool rectangle;
    std::vector<std::size_t> members;
  };
  std::vector<Group> groups;
  for (int s = 0; s < 2; ++s) {
    for (auto& by_length : split(shapes[s], log_length, o.split_log_gap)) {
      if (s == 1) {
        groups.push_back({false, std::move(by_length)});
        continue;
      }
      for (auto& by_width : split(std::move(by_length), log_width, o.split_log_gap))
        groups.push_back({true, std::move(by_width)});
    }
  }
  std::stable_sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) {
    return a.members.size() > b.members.size();
  });
  std::vector<vision::LampShapePrior> kinds;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const std::size_t n = groups[g].members.size();
    if (g > 0 && (static_cast<int>(n) < o.min_sightings ||
                  static_cast<double>(n) < o.min_share * static_cast<double>(looks.size())))
      break;
    std::vector<double> lengths, widths;
    for (const std::size_t i : groups[g].members) {
      lengths.push_back(looks[i].length);
      widths.push_back(looks[i].width);
    }
    vision::LampShapePrior p;
    p.rectangle = groups[g].rectangle;
    p.length = median(lengths);
    p.width = p.rectangle ? median(widths) : p.length;
    p.min_distance = o.min_distance;
    p.nominal_distance = 1.0;
    p.max_distance = o.max_distance;
    kinds.push_back(p);
  }
  return kinds;
}

int nearest_kind(const std::vector<vision::LampShapePrior>& kinds, double length, double width) {
  length = std::max(length, 1e-9);
  width = std::max(width, 1e-9);
  const bool long_lamp = is_long(length, width);
  const bool any_of_shape = std::any_of(kinds.begin(), kinds.end(),
                                        [&](const auto& k) { return k.rectangle == long_lamp; });
  int best = -1;
  double best_d = 0;
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    if (any_of_shape && kinds[k].rectangle != long_lamp) continue;
    double d = std::abs(std::log(length / kinds[k].length));
    if (long_lamp && kinds[k].rectangle) d += std::abs(std::log(width / kinds[k].width));
    if (best < 0 || d < best_d) {
      best = static_cast<int>(k);
      best_d = d;
    }
  }
  return best;
}

}  // namespace lampnav::mapping
