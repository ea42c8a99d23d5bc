#include "lampnav/graph/geojson.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <unordered_map>

#include "lampnav/graph/map_checks.hpp"
#include "lampnav/internal/json_util.hpp"
#include "nav2_rules.hpp"

namespace lampnav::graph {

using Eigen::Vector2d;
using json::Cursor;
using json::Json;

namespace {

// A feature read from the file, before the cross-feature checks.
struct ParsedFeature {
  std::size_t index = 0;
  std::string place;  // "features[3] (id 12)"
  bool is_node = false;
  Node node;
  Edge edge;
};

Vector2d read_xy(const Cursor& c) {
  c.array_size(2, 2);
  return {c[0].number(), c[1].number()};
}

Polygon read_region(const Cursor& c) {
  c.only_keys({"x_values", "y_values"});
  const Cursor xs = c.at("x_values");
  const Cursor ys = c.at("y_values");
  const std::size_t n = xs.array_size();
  if (ys.array_size() != n) {
    ys.fail("has " + std::to_string(ys.value().size()) + " values but x_values has " +
            std::to_string(n));
  }
  std::vector<Vector2d> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) v.emplace_back(xs[i].number(), ys[i].number());
  // A closing vertex equal to the first is a common GIS habit; it adds nothing.
  if (v.size() > 3 && v.front() == v.back()) v.pop_back();
  if (v.size() < 3) c.fail("degenerate region: fewer than 3 vertices");
  Polygon poly(std::move(v));
  if (poly.self_intersects()) c.fail("degenerate region: self-intersecting");
  if (poly.area() < 1e-9) c.fail("degenerate region: zero area");
  return poly;
}

Lamp read_lamp(const Cursor& c, const Node& owner) {
  c.only_keys({"id", "xyz", "yaw", "shape", "size"});
  Lamp l;
  l.id = LampId(c.at("id").string());
  const Cursor xyz = c.at("xyz");
  xyz.array_size(3, 3);
  l.xyz = {xyz[0].number(), xyz[1].number(), xyz[2].number()};
  if (l.xyz.z() <= 0)
    xyz.fail("lamp height z must be above the floor (> 0), found " + xyz[2].value().dump());
  const std::string shape = c.at("shape").string();
  const Cursor size = c.at("size");
  if (shape == "rectangle") {
    l.shape = LampShape::rectangle;
    size.array_size(2, 2);
    l.length = size[0].positive();
    l.width = size[1].positive();
    if (l.length < l.width) size.fail("a rectangle's size is [length, width] with length >= width");
    l.yaw = c.at("yaw").number();  // a rectangle's orientation matters: no default
    l.yaw_given = true;
  } else if (shape == "disc") {
    l.shape = LampShape::disc;
    size.array_size(1, 1);
    l.length = l.width = size[0].positive();
    if (auto yaw = c.find("yaw")) {
      l.yaw = yaw->number();
      l.yaw_given = true;
    }
  } else {
    c.at("shape").fail("unknown lamp shape '" + shape + "' (expected rectangle or disc)");
  }
  if (!owner.region.contains(l.xyz.head<2>(), 1e-6)) {
    xyz.fail("lamp '" + l.id.value + "' lies outside its node's region");
  }
  return l;
}

// Which layout a file has (map-format.md): format 1 keeps lamps, doors and the axis (as
// [[x, y], [x, y]]) in `metadata`; format 2 keeps lamps and doors in `properties.lampnav` (which
// Nav2 ignores) and the axis as x_values/y_values; a file with no `lampnav` block is a plain Nav2
// graph.
enum class Layout { format1, format2, nav2 };

// The members of `c` not named in `read`, as JSON object text (empty when there are none).
std::string kept_keys(const Cursor& c, std::initializer_list<const char*> read) {
  Json kept = Json::object();
  for (auto it = c.value().begin(); it != c.value().end(); ++it) {
    bool known = false;
    for (const char* k : read) known = known || it.key() == k;
    if (!known) kept[it.key()] = it.value();
  }
  return kept.empty() ? std::string() : kept.dump();
}

void read_doors(const Cursor& doors, Node& n) {
  const std::size_t count = doors.array_size();
  if (count > 0 && !n.axis) doors.fail("doors are placed along an axis; this node has none");
  std::set<std::string> names;
  for (std::size_t i = 0; i < count; ++i) {
    const Cursor d = doors[i];
    d.only_keys({"name", "side", "at"});
    Door door;
    door.name = d.at("name").string();
    if (!names.insert(door.name).second) d.at("name").fail("duplicate door name in this node");
    const std::string side = d.at("side").string();
    if (side == "left") {
      door.side = Side::left;
    } else if (side == "right") {
      door.side = Side::right;
    } else {
      d.at("side").fail("side must be \"left\" or \"right\", found \"" + side + "\"");
    }
    door.at = d.at("at").number();
    if (door.at < 0 || door.at > n.length() + 1e-9) {
      d.at("at").fail("door lies outside the corridor (0 to " + std::to_string(n.length()) + " m)");
    }
    n.doors.push_back(std::move(door));
  }
}

Axis read_axis(const Cursor& axis, Layout layout) {
  Axis a;
  if (layout == Layout::format1) {
    axis.array_size(2, 2);
    a = Axis{read_xy(axis[0]), read_xy(axis[1])};
  } else {
    axis.only_keys({"x_values", "y_values"});
    const Cursor xs = axis.at("x_values"), ys = axis.at("y_values");
    xs.array_size(2, 2);
    ys.array_size(2, 2);
    a = Axis{{xs[0].number(), ys[0].number()}, {xs[1].number(), ys[1].number()}};
  }
  if (a.length() < 1e-6) axis.fail("axis has zero length");
  return a;
}

void check_frame(const Cursor& props) {
  if (auto frame = props.find("frame")) {
    if (frame->string() != "map")
      frame->fail("frame must be \"map\" (lampnav reads graphs in the map frame only), found " +
                  frame->value().dump());
  }
}

// A node of a plain Nav2 graph: a waypoint named by metadata.name when that is a string, else by
// its id; Nav2's metadata and operations are kept, checked against Nav2's loader.
Node read_waypoint(const Cursor& feature, const Cursor& props) {
  Node n;
  n.id = NodeId(nav2::id(props.at("id")));
  check_frame(props);
  n.place = Place::waypoint;
  n.point = read_xy(feature.at("geometry").at("coordinates"));
  n.name = std::to_string(n.id.value);
  if (auto md = props.find("metadata")) {
    nav2::check_metadata(*md);
    if (auto name = md->find("name");
        name && name->value().is_string() && !name->value().get<std::string>().empty())
      n.name = name->value().get<std::string>();
  }
  if (auto ops = props.find("operations")) nav2::check_operations(*ops);
  n.nav2_keys = kept_keys(props, {"id"});
  return n;
}

Node read_node(const Cursor& feature, const Cursor& props, Layout layout) {
  const Cursor geom = feature.at("geometry");
  geom.only_keys({"type", "coordinates"});
  if (layout == Layout::nav2) return read_waypoint(feature, props);
  if (layout == Layout::format1)
    props.only_keys({"id", "frame", "metadata"});
  else
    props.only_keys({"id", "frame", "metadata", "lampnav", "operations"});
  Node n;
  n.id = NodeId(nav2::id(props.at("id")));
  check_frame(props);
  n.point = read_xy(geom.at("coordinates"));
  if (auto ops = props.find("operations")) nav2::check_operations(*ops);
  n.nav2_keys = kept_keys(props, {"id", "frame", "metadata", "lampnav"});

  const Cursor md = props.at("metadata");
  if (layout == Layout::format1)
    md.only_keys({"name", "place", "axis", "width", "region", "doors", "lamps", "length"});
  else
    md.only_keys({"name", "place", "axis", "width", "region", "length"});
  std::optional<Cursor> extra;  // where lamps and doors are
  if (layout == Layout::format1) {
    extra = md;
  } else if (auto ln = props.find("lampnav")) {
    ln->only_keys({"lamps", "doors"});
    extra = *ln;
  }
  n.name = md.at("name").string();
  const Cursor place = md.at("place");
  const auto kind = place_from_string(place.string());
  if (!kind) {
    place.fail("unknown place '" + place.value().get<std::string>() +
               "' (expected corridor, junction, corner, end, door, hall or room)");
  }
  n.place = *kind;
  n.region = read_region(md.at("region"));
  if (auto axis = md.find("axis")) {
    n.axis = read_axis(*axis, layout);
  } else if (n.place == Place::corridor) {
    md.at("axis");  // throws "missing": a corridor needs its centreline
  }
  if (auto width = md.find("width")) n.width = width->positive();
  if (auto length = md.find("length")) n.length_override = length->positive();
  if (auto doors = extra ? extra->find("doors") : std::nullopt) read_doors(*doors, n);
  if (auto lamps = extra ? extra->find("lamps") : std::nullopt) {
    const std::size_t count = lamps->array_size();
    for (std::size_t i = 0; i < count; ++i) n.lamps.push_back(read_lamp((*lamps)[i], n));
  }
  return n;
}

// An edge; its cost is settled once the node points are known (settle_cost).
Edge read_edge(const Cursor& feature, const Cursor& props, Layout layout,
               std::vector<MapWarning>& warnings) {
  if (layout == Layout::format1)
    props.only_keys({"id", "startid", "endid", "cost", "metadata", "overridable"});
  else if (layout == Layout::format2)
    props.only_keys({"id", "startid", "endid", "cost", "metadata", "overridable", "operations"});
  Edge e;
  e.id = EdgeId(nav2::id(props.at("id")));
  e.start = NodeId(nav2::id(props.at("startid")));
  e.end = NodeId(nav2::id(props.at("endid")));
  if (auto cost = props.find("cost")) {
    const double c = cost->number();
    if (c < 0) cost->fail("cost must not be negative");
    e.cost_given = c;
  }
  if (auto ov = props.find("overridable")) e.overridable = ov->boolean();
  if (layout == Layout::format1 && e.cost_given) {
    e.overridable = false;  // format 1's cost was the cost; Nav2 needs the flag to agree
  }
  if (e.overridable == false && !(e.cost_given.value_or(0.0) > 0.0)) {
    (props.find("cost") ? props.at("cost") : props.at("overridable"))
        .fail(
            "an edge with \"overridable\": false needs a positive cost (Nav2's planner throws "
            "on a cost of 0)");
  }
  if (auto md = props.find("metadata")) {
    if (layout == Layout::format1)
      md->only_keys({});
    else
      nav2::check_metadata(*md);
  }
  if (auto ops = props.find("operations")) nav2::check_operations(*ops);
  e.nav2_keys = kept_keys(props, {"id", "startid", "endid", "cost", "overridable"});
  const Cursor geom = feature.at("geometry");
  try {
    geom.only_keys({"type", "coordinates"});
    e.line_string = geom.at("type").string() == "LineString";
    const Cursor coords = geom.at("coordinates");
    auto read_line = [&](const Cursor& line) {
      const std::size_t np = line.array_size(2);
      std::vector<Vector2d> pts;
      for (std::size_t k = 0; k < np; ++k) pts.push_back(read_xy(line[k]));
      e.geometry.push_back(std::move(pts));
    };
    if (e.line_string) {
      read_line(coords);
    } else {
      const std::size_t nl = coords.array_size(1);
      for (std::size_t i = 0; i < nl; ++i) read_line(coords[i]);
    }
  } catch (const InputError& bad) {
    if (layout != Layout::nav2) throw;
    // Nav2 never reads an edge's geometry; a plain graph's odd one is kept and warned about.
    e.geometry.clear();
    e.nav2_geometry = geom.value().dump();
    warnings.push_back({bad.where(), bad.message() +
                                         " (Nav2 ignores edge geometry; kept as it is, drawn as "
                                         "the straight line)"});
  }
  return e;
}

// The cost planning uses, as Nav2 scores the edge: the written cost when it may not be
// overridden, else the straight line between the node points (format 1: the polyline's length).
void settle_cost(Edge& e, const Node& start, const Node& end, Layout layout) {
  if (e.geometry.empty()) e.geometry.push_back({start.point, end.point});
  if (e.cost_given && e.overridable == false)
    e.cost = *e.cost_given;
  else if (layout == Layout::format1)
    e.cost = e.geometric_length();
  else
    e.cost = (end.point - start.point).norm();
}

std::string feature_place(std::size_t index, const Json& feature) {
  std::string place = "features[" + std::to_string(index) + "]";
  if (feature.is_object()) {
    auto p = feature.find("properties");
    if (p != feature.end() && p->is_object()) {
      auto id = p->find("id");
      if (id != p->end() && id->is_number()) place += " (id " + id->dump() + ")";
    }
  }
  return place;
}

}  // namespace

LoadedMap parse_map(const std::string& text, const std::string& source) {
  const Json doc = json::parse(text, source);
  const Cursor root(doc, {source, "", ""});
  root.expect_object();
  {
    auto type = doc.find("type");
    if (type == doc.end() || *type != "FeatureCollection") {
      root.at("type").fail("not a GeoJSON FeatureCollection");
    }
  }
  Layout layout = Layout::nav2;
  if (auto ln = root.find("lampnav")) {
    root.only_keys({"type", "name", "lampnav", "features", "crs", "bbox", "date_generated"});
    ln->only_keys({"format", "units", "frame"});
    const Cursor format = ln->at("format");
    const Json& fv = format.value();
    if (!fv.is_number_integer() || (fv.get<std::int64_t>() != 1 && fv.get<std::int64_t>() != 2)) {
      format.fail("unknown map format " + fv.dump() + " (this reader knows formats 1 and 2)");
    }
    layout = fv.get<std::int64_t>() == 1 ? Layout::format1 : Layout::format2;
    if (auto units = ln->find("units")) {
      if (units->string() != "m") units->fail("units must be \"m\"");
    }
    if (auto frame = ln->find("frame")) {
      if (frame->string() != "map") frame->fail("frame must be \"map\"");
    }
  }
  std::string name;
  if (auto n = root.find("name")) name = n->string();

  const Cursor features = root.at("features");
  const std::size_t count = features.array_size();
  std::vector<InputError> problems;
  std::vector<MapWarning> warnings;
  std::vector<ParsedFeature> parsed;
  parsed.reserve(count);
  std::set<std::int64_t> failed_ids;
  for (std::size_t i = 0; i < count; ++i) {
    const Json& fj = features.value()[i];
    ErrorContext where{source, feature_place(i, fj), ""};
    const Cursor f(fj, where);
    try {
      f.only_keys({"type", "geometry", "properties", "id"});
      if (f.at("type").string() != "Feature") f.at("type").fail("expected \"Feature\"");
      const Cursor props = f.at("properties");
      const std::string gtype = f.at("geometry").at("type").string();
      ParsedFeature pf;
      pf.index = i;
      pf.place = where.place;
      if (gtype == "Point") {
        pf.is_node = true;
        pf.node = read_node(f, props, layout);
      } else if (gtype == "MultiLineString" || gtype == "LineString") {
        pf.edge = read_edge(f, props, layout, warnings);
      } else {
        f.at("geometry")
            .at("type")
            .fail("expected Point (a node) or MultiLineString or LineString (an edge), found \"" +
                  gtype + "\"");
      }
      parsed.push_back(std::move(pf));
    } catch (const InputError& e) {
      problems.push_back(e);
      // Remember the id of a feature that failed, so edges naming it are not also reported.
      if (fj.is_object() && fj.contains("properties") && fj["properties"].is_object() &&
          fj["properties"].contains("id") && fj["properties"]["id"].is_number_integer()) {
        failed_ids.insert(fj["properties"]["id"].get<std::int64_t>());
      }
    }
  }

  // Cross-feature checks: unique ids, names and lamp ids; edges naming nodes; overlapping regions.
  std::unordered_map<std::int64_t, const ParsedFeature*> by_id;
  std::unordered_map<std::string, const ParsedFeature*> by_name;
  std::unordered_map<std::string, const ParsedFeature*> by_lamp;
  auto problem = [&](const ParsedFeature& f, const std::string& field, const std::string& msg) {
    problems.emplace_back(ErrorContext{source, f.place, field}, msg);
  };
  const std::string lamps_field =
      layout == Layout::format1 ? "properties.metadata.lamps[" : "properties.lampnav.lamps[";
  for (const auto& f : parsed) {
    const std::int64_t id = f.is_node ? f.node.id.value : f.edge.id.value;
    auto [it, fresh] = by_id.emplace(id, &f);
    if (!fresh && layout == Layout::nav2 && !f.is_node && !it->second->is_node) {
      // Nav2 loads edges that share an id; only operations and blocks naming it are ambiguous.
      warnings.push_back({ErrorContext{source, f.place, "properties.id"},
                          "duplicate edge id " + std::to_string(id) + " (also " +
                              it->second->place +
                              "); Nav2 loads it, but an edge block or "
                              "operation naming this id is ambiguous"});
    } else if (!fresh) {
      problem(f, "properties.id",
              "duplicate id " + std::to_string(id) + " (also " + it->second->place + ")");
    }
    if (!f.is_node) continue;
    auto [nit, nfresh] = by_name.emplace(f.node.name, &f);
    if (!nfresh)
      problem(f, "properties.metadata.name",
              "duplicate name '" + f.node.name + "' (also " + nit->second->place + ")");
    for (std::size_t k = 0; k < f.node.lamps.size(); ++k) {
      auto [lit, lfresh] = by_lamp.emplace(f.node.lamps[k].id.value, &f);
      if (!lfresh) {
        problem(f, lamps_field + std::to_string(k) + "].id",
                "duplicate lamp id '" + f.node.lamps[k].id.value + "' (also " + lit->second->place +
                    ")");
      }
    }
  }
  std::set<std::int64_t> node_ids = failed_ids;
  for (const auto& f : parsed) {
    if (f.is_node) node_ids.insert(f.node.id.value);
  }
  for (const auto& f : parsed) {
    if (f.is_node) continue;
    if (!node_ids.count(f.edge.start.value)) {
      problem(f, "properties.startid",
              "names no node (" + std::to_string(f.edge.start.value) + ")");
    }
    if (!node_ids.count(f.edge.end.value)) {
      problem(f, "properties.endid", "names no node (" + std::to_string(f.edge.end.value) + ")");
    }
    if (f.edge.start == f.edge.end && layout == Layout::nav2) {
      warnings.push_back({ErrorContext{source, f.place, "properties.endid"},
                          "edge starts and ends at the same node (Nav2 loads it; no route "
                          "takes it)"});
    } else if (f.edge.start == f.edge.end) {
      problem(f, "properties.endid", "edge starts and ends at the same node");
    }
  }
  // Overlapping regions: sweep the nodes by their boxes' left edges so only neighbours are paired.
  std::vector<const ParsedFeature*> nodes;
  for (const auto& f : parsed) {
    if (f.is_node && f.node.region.size() >= 3) nodes.push_back(&f);
  }
  std::sort(nodes.begin(), nodes.end(), [](const auto* a, const auto* b) {
    return a->node.region.bounds().min.x() < b->node.region.bounds().min.x();
  });
  for (std::size_t a = 0; a < nodes.size(); ++a) {
    const Polygon& ra = nodes[a]->node.region;
    for (std::size_t b = a + 1; b < nodes.size(); ++b) {
      const Polygon& rb = nodes[b]->node.region;
      if (rb.bounds().min.x() > ra.bounds().max.x()) break;
      if (!ra.bounds().intersects(rb.bounds())) continue;
      const double overlap = intersection_area(ra, rb);
      if (overlap > kRegionOverlapTolerance) {
        const auto* later = nodes[a]->index > nodes[b]->index ? nodes[a] : nodes[b];
        const auto* earlier = later == nodes[a] ? nodes[b] : nodes[a];
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3f", overlap);
        problem(*later, "properties.metadata.region",
                "region overlaps the region of '" + earlier->node.name + "' (" + earlier->place +
                    ") by " + buf + " m^2");
      }
    }
  }
  // Nav2's loader refuses a graph without nodes or without edges ("The graph is malformed").
  if (problems.empty()) {
    std::size_t node_count = 0;
    for (const auto& f : parsed) node_count += f.is_node ? 1 : 0;
    if (node_count == 0 || node_count == parsed.size()) {
      problems.emplace_back(ErrorContext{source, "", "features"},
                            std::string("a map needs at least one node and one edge (Nav2's route "
                                        "graph loader refuses it otherwise); this one has ") +
                                (node_count == 0 ? "no node" : "no edge"));
    }
  }
  if (!problems.empty()) {
    std::stable_sort(problems.begin(), problems.end(),
                     [](const InputError& x, const InputError& y) {
                       return x.where().place.size() != y.where().place.size()
                                  ? x.where().place.size() < y.where().place.size()
                                  : x.where().place < y.where().place;
                     });
    throw InputErrors(std::move(problems));
  }

  LoadedMap out{TopologicalMap(name), {}};
  if (layout == Layout::nav2) {
    out.map.set_plain_nav2(true);
    out.map.set_nav2_keys(kept_keys(root, {"type", "name", "features"}));
  } else {
    out.map.set_nav2_keys(kept_keys(root, {"type", "name", "features", "lampnav"}));
  }
  for (auto& f : parsed) {
    if (f.is_node) out.map.add_node(std::move(f.node));
  }
  for (auto& f : parsed) {
    if (f.is_node) continue;
    settle_cost(f.edge, out.map.node(f.edge.start), out.map.node(f.edge.end), layout);
    if (f.edge.cost_given && f.edge.overridable != false) {
      warnings.push_back({ErrorContext{source, f.place, "properties.cost"},
                          "Nav2 ignores a cost without \"overridable\": false and scores the "
                          "straight line between the nodes; lampnav does the same"});
    }
    out.map.add_edge(std::move(f.edge));
  }
  out.warnings = std::move(warnings);
  for (auto& w : check_map(out.map, {}, source)) out.warnings.push_back(std::move(w));
  return out;
}

LoadedMap read_map(const std::string& path) { return parse_map(json::read_file(path), path); }

void save_map(const TopologicalMap& map, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error(path + ": cannot open the file for writing");
  out << write_map(map);
  if (!out) throw Error(path + ": write error");
}

}  // namespace lampnav::graph
