#pragma once
// The median of a few values (the upper one of an even count); 0 for none. Private to mapping/.

#include <algorithm>
#include <vector>

namespace lampnav::mapping {

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace lampnav::mapping
