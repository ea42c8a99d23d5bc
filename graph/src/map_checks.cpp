#include "lampnav/graph/map_checks.hpp"

#include <algorithm>
#include <boost/graph/strong_components.hpp>
#include <cmath>
#include <cstdio>

#include "map_impl.hpp"

namespace lampnav::graph {

double max_speed_every_lamp_seen(double view_length, double lamp_extent, double spacing,
                                 double frame_rate) {
  const double fit = view_length - lamp_extent;
  if (!(fit > 0) || !(frame_rate > 0)) return 0.0;
  return frame_rate * std::min(fit, spacing / 2.0);
}

namespace {
std::string node_place(const Node& n) {
  return "node '" + n.name + "' (id " + std::to_string(n.id.value) + ")";
}
std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}
}  // namespace

std::vector<MapWarning> check_camera_coverage(const TopologicalMap& map, const CeilingCoverage& cov,
                                              const std::string& file) {
  std::vector<MapWarning> out;
  const Graph& g = map.impl().g;
  const std::size_t n = boost::num_vertices(g);
  for (std::size_t v = 0; v < n; ++v) {
    const Node& node = g[v];
    if (node.place != Place::corridor || !node.axis || node.lamps.empty()) continue;
    const double heading = std::atan2(node.axis->direction().y(), node.axis->direction().x());
    double worst = INFINITY;
    std::size_t worst_i = 0;
    for (std::size_t i = 0; i < node.lamps.size(); ++i) {
      const Lamp& l = node.lamps[i];
      double spacing = INFINITY;
      if (i + 1 < node.lamps.size()) spacing = (node.lamps[i + 1].xyz - l.xyz).head<2>().norm();
      if (i > 0) spacing = std::min(spacing, (node.lamps[i - 1].xyz - l.xyz).head<2>().norm());
      const double vmax = max_speed_every_lamp_seen(
          cov.view_length(l.xyz.z()), l.extent_along(heading), spacing, cov.frame_rate);
      if (vmax < worst) {
        worst = vmax;
        worst_i = i;
      }
    }
    if (worst < cov.speed) {
      out.push_back(
          {{file, node_place(node), "properties.lampnav.lamps[" + std::to_string(worst_i) + "]"},
           "at " + fmt(cov.speed) + " m/s and " + fmt(cov.frame_rate) +
               " frames/s the ceiling camera could miss or confuse lamp '" +
               node.lamps[worst_i].id.value + "'; the highest safe speed here is " + fmt(worst) +
               " m/s"});
    }
  }
  return out;
}

std::vector<MapWarning> check_map(const TopologicalMap& map, const MapCheckOptions& options,
                                  const std::string& file) {
  std::vector<MapWarning> out;
  const Graph& g = map.impl().g;
  const std::size_t n = boost::num_vertices(g);

  for (std::size_t v = 0; v < n; ++v) {
    if (n > 1 && boost::in_degree(v, g) == 0) {
      out.push_back({{file, node_place(g[v]), ""}, "no edge reaches this node"});
    }
  }
  // Nodes outside the largest strongly connected component cannot reach, or cannot be reached
  // from, the rest of the building.
  if (n > 1) {
    std::vector<int> comp(n);
    const int ncomp = boost::strong_components(
        g, boost::make_iterator_property_map(comp.begin(), boost::get(boost::vertex_index, g)));
    if (ncomp > 1) {
      std::vector<int> size(static_cast<std::size_t>(ncomp), 0);
      for (int c : comp) ++size[static_cast<std::size_t>(c)];
      const int main = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
      for (std::size_t v = 0; v < n; ++v) {
        if (comp[v] != main && boost::in_degree(v, g) > 0) {
          out.push_back({{file, node_place(g[v]), ""},
                         "not mutually reachable with the rest of the map (a one-way dead end or a "
                         "separate part)"});
        }
      }
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (g[v].place == Place::corridor && g[v].lamps.empty()) {
      out.push_back({{file, node_place(g[v]), "properties.lampnav.lamps"},
                     "corridor without lamps: the ceiling camera cannot localize here"});
    }
  }
  if (options.coverage) {
    const auto coverage = check_camera_coverage(map, *options.coverage, file);
    out.insert(out.end(), coverage.begin(), coverage.end());
  }
  return out;
}

}  // namespace lampnav::graph
