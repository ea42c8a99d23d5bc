#pragma once
// Helpers of the `lampnav map build` end-to-end tests: a drive recorded by `lampnav sim`, and a
// built map's lamps against the true ones.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "cli_support.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/mapping/rigid_fit.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

struct Recorded {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("lampnav_map_build_" + std::to_string(::getpid()));
  std::string log = (dir / "drive.mcap").string();
  // The drive E1 -> K2 (unless `flags` give a --route) on `map` (the office floor's file unless
  // given) by `robot` (the bundled one unless given), `sim` flags added.
  explicit Recorded(const std::string& map = test::source_path("maps/office_floor.geojson"),
                    const std::string& flags = "",
                    const std::string& robot = test::source_path("maps/robots/pioneer.json")) {
    std::filesystem::create_directories(dir);
    const std::string route =
        flags.find("--route") == std::string::npos ? "--route 'E1 -> K2' " : "";
    const auto r = test::run_lampnav("sim " + route + "--map '" + map + "' --robot '" + robot +
                                     "' -o '" + log + "' " + flags);
    EXPECT_EQ(r.status, 0) << r.err;
  }
  ~Recorded() { std::filesystem::remove_all(dir); }
};

// A built map's lamps against the true ones: each moved into the true map's frame by the
// drive's first true pose and paired with the true lamp within 0.3 m; the errors after the best
// rigid alignment (the map's frame is the drive's start). A lamp with no true lamp there, or a
// true lamp matched twice, fails the test.
struct LampErrors {
  std::set<std::string> matched;             // true lamp ids
  std::map<std::string, std::string> built;  // the built lamp's id on each true one
  std::map<std::string, double> error;       // m, on each true one, after the alignment
  double rms = 0, worst = 0;
};

inline LampErrors lamp_errors(const graph::TopologicalMap& built,
                              const graph::TopologicalMap& truth, const Pose2& start,
                              double within_m = 0.3) {
  LampErrors e;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> pairs;
  std::vector<std::string> ids;  // the true lamp of each pair
  for (const auto& n : built.nodes()) {
    for (const auto& l : n.lamps) {
      const Eigen::Vector2d at = start.transform_from(l.xyz.head<2>());
      const auto near = truth.lamps_within(at, within_m);
      if (near.empty()) {
        ADD_FAILURE() << l.id.value << " at " << at.transpose() << ": no true lamp there";
        continue;
      }
      e.built[near.front()->id.value] = l.id.value;
      if (!e.matched.insert(near.front()->id.value).second)
        ADD_FAILURE() << "twice: " << near.front()->id.value;
      pairs.emplace_back(l.xyz.head<2>(), near.front()->xyz.head<2>());
      ids.push_back(near.front()->id.value);
    }
  }
  const Pose2 fit = mapping::fit_rigid(pairs);
  double sum = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& [b, t] = pairs[k];
    const double err = (fit.transform_from(b) - t).norm();
    e.error[ids[k]] = err;
    e.worst = std::max(e.worst, err);
    sum += err * err;
  }
  e.rms = std::sqrt(sum / std::max<std::size_t>(1, pairs.size()));
  return e;
}

}  // namespace lampnav::test
