// Writes maps in format 2 (map-format.md): what Nav2's route graph loader reads under `metadata`,
// lampnav's lamps and doors under `properties.lampnav`, Nav2's own keys written back as they came.
// A plain Nav2 graph is written back as a plain Nav2 graph.

#include <cmath>

#include <nlohmann/json.hpp>

#include "lampnav/graph/geojson.hpp"

namespace lampnav::graph {

using Eigen::Vector2d;

namespace {

using OJson = nlohmann::ordered_json;

OJson xy(const Vector2d& p) { return OJson::array({p.x(), p.y()}); }

// Appends the members of kept JSON object text (Nav2's keys lampnav did not read) to `out`.
void append_kept(OJson& out, const std::string& kept) {
  if (kept.empty()) return;
  const OJson k = OJson::parse(kept);
  for (auto it = k.begin(); it != k.end(); ++it) out[it.key()] = it.value();
}

OJson lamp_json(const Lamp& l) {
  OJson lj;
  lj["id"] = l.id.value;
  lj["xyz"] = {l.xyz.x(), l.xyz.y(), l.xyz.z()};
  if (l.yaw_given) lj["yaw"] = l.yaw;
  lj["shape"] = to_string(l.shape);
  lj["size"] = l.shape == LampShape::rectangle ? OJson::array({l.length, l.width})
                                               : OJson::array({l.length});
  return lj;
}

OJson node_properties(const Node& n, bool plain) {
  OJson props;
  props["id"] = n.id.value;
  if (plain) {  // a Nav2 waypoint: its frame, metadata and operations as they came
    append_kept(props, n.nav2_keys);
    return props;
  }
  props["frame"] = "map";
  OJson md;
  md["name"] = n.name;
  md["place"] = to_string(n.place);
  if (n.axis) {
    md["axis"] = {{"x_values", {n.axis->first.x(), n.axis->second.x()}},
                  {"y_values", {n.axis->first.y(), n.axis->second.y()}}};
  }
  if (n.width) md["width"] = *n.width;
  if (n.length_override) md["length"] = *n.length_override;
  OJson xs = OJson::array(), ys = OJson::array();
  for (const auto& v : n.region.vertices()) {
    xs.push_back(v.x());
    ys.push_back(v.y());
  }
  md["region"] = {{"x_values", xs}, {"y_values", ys}};
  props["metadata"] = md;
  OJson ln;
  if (!n.doors.empty()) {
    OJson doors = OJson::array();
    for (const auto& d : n.doors)
      doors.push_back({{"name", d.name}, {"side", to_string(d.side)}, {"at", d.at}});
    ln["doors"] = doors;
  }
  OJson lamps = OJson::array();
  for (const auto& l : n.lamps) lamps.push_back(lamp_json(l));
  ln["lamps"] = lamps;
  props["lampnav"] = ln;
  append_kept(props, n.nav2_keys);
  return props;
}

OJson edge_properties(const TopologicalMap& map, const Edge& e) {
  OJson props = {{"id", e.id.value}, {"startid", e.start.value}, {"endid", e.end.value}};
  const double line = (map.node(e.end).point - map.node(e.start).point).norm();
  if (e.cost_given) {
    props["cost"] = *e.cost_given;
    if (e.overridable) props["overridable"] = *e.overridable;
  } else if (std::fabs(e.cost - line) > 1e-9 * std::max(1.0, line)) {
    // Not the straight line Nav2 would score: written, and marked so Nav2 keeps it.
    props["cost"] = e.cost;
    props["overridable"] = false;
  }
  if (!map.plain_nav2()) props["metadata"] = OJson::object();  // Nav2's kept one replaces it
  append_kept(props, e.nav2_keys);
  return props;
}

OJson edge_geometry(const Edge& e) {
  if (!e.nav2_geometry.empty()) return OJson::parse(e.nav2_geometry);
  OJson lines = OJson::array();
  for (const auto& line : e.geometry) {
    OJson l = OJson::array();
    for (const auto& p : line) l.push_back(xy(p));
    lines.push_back(l);
  }
  if (e.line_string && lines.size() == 1)
    return {{"type", "LineString"}, {"coordinates", lines[0]}};
  return {{"type", "MultiLineString"}, {"coordinates", lines}};
}

}  // namespace

std::string write_map(const TopologicalMap& map) {
  const bool plain = map.plain_nav2();
  OJson doc;
  doc["type"] = "FeatureCollection";
  if (!map.name().empty()) doc["name"] = map.name();
  if (!plain) doc["lampnav"] = {{"format", kMapFormat}, {"units", "m"}, {"frame", "map"}};
  append_kept(doc, map.nav2_keys());
  OJson features = OJson::array();
  for (const Node& n : map.nodes()) {
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", xy(n.point)}}},
                        {"properties", node_properties(n, plain)}});
  }
  for (const Edge& e : map.edges()) {
    features.push_back({{"type", "Feature"},
                        {"geometry", edge_geometry(e)},
                        {"properties", edge_properties(map, e)}});
  }
  doc["features"] = features;
  return doc.dump(1) + "\n";
}

}  // namespace lampnav::graph
