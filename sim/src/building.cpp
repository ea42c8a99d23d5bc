#include "lampnav/sim/building.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <vector>

#include "lampnav/core/error.hpp"

namespace lampnav::sim {

using Json = nlohmann::ordered_json;

void BuildingOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"", "building", field}, what);
  };
  check(nodes >= 8 && nodes <= 200000, "nodes", "must be 8 to 200000");
  check(block_m >= 8 && block_m <= 200, "block_m", "must be 8 to 200 m");
  check(lamp_spacing_m >= 0.5 && lamp_spacing_m < block_m, "lamp_spacing_m",
        "must be at least 0.5 m and less than a block");
  check(ceiling_m > 1 && ceiling_m < 50, "ceiling_m", "must be 1 to 50 m");
  check(missing_corridors >= 0 && missing_corridors <= 1000, "missing_corridors",
        "must be 0 to 1000");
  check(wing_lamp_spacing_m == 0 || (wing_lamp_spacing_m >= 0.5 && wing_lamp_spacing_m < block_m),
        "wing_lamp_spacing_m", "must be 0 (none) or at least 0.5 m and less than a block");
  check(rows == 1 || rows == 2, "rows", "must be 1 or 2");
  check(row_spacing_m >= 0.5 && row_spacing_m <= 1.8, "row_spacing_m",
        "must be 0.5 to 1.8 m (the rows stay inside the 2 m corridor)");
}

namespace {

struct Writer {
  Json features = Json::array();
  int next_id = 1, next_edge = 1000000, lamps = 0, edges = 0;
  std::map<std::string, int> ids;
  std::map<std::string, std::pair<double, double>> points;

  static Json region(double x0, double y0, double x1, double y1) {
    return {{"x_values", {x0, x1, x1, x0}}, {"y_values", {y0, y0, y1, y1}}};
  }
  // A place in map format 2: what Nav2 reads in `metadata`, lamps and doors in `lampnav`. Returns
  // the feature's properties.
  Json& node(const std::string& name, const char* place, double x, double y, Json region_json) {
    ids[name] = next_id;
    points[name] = {x, y};
    Json md = {{"name", name}, {"place", place}};
    md["region"] = std::move(region_json);
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", {x, y}}}},
                        {"properties",
                         {{"id", next_id++},
                          {"frame", "map"},
                          {"metadata", md},
                          {"lampnav", {{"lamps", Json::array()}}}}}});
    return features.back()["properties"];
  }
  void lamp(Json& props, const std::string& id, double x, double y, double z, double yaw,
            bool disc) {
    Json l = {{"id", id}, {"xyz", {x, y, z}}};
    if (disc) {
      l["shape"] = "disc";
      l["size"] = {0.6};
    } else {
      l["yaw"] = yaw;
      l["shape"] = "rectangle";
      l["size"] = {1.2, 0.3};
    }
    props["lampnav"]["lamps"].push_back(std::move(l));
    ++lamps;
  }
  void link(const std::string& a, const std::string& b) {
    for (const auto& [s, e] : {std::pair{a, b}, std::pair{b, a}}) {
      const auto [sx, sy] = points.at(s);
      const auto [ex, ey] = points.at(e);
      features.push_back(
          {{"type", "Feature"},
           {"geometry", {{"type", "MultiLineString"}, {"coordinates", {{{sx, sy}, {ex, ey}}}}}},
           {"properties",
            {{"id", next_edge++},
             {"startid", ids.at(s)},
             {"endid", ids.at(e)},
             {"metadata", Json::object()}}}});
      ++edges;
    }
  }
};

}  // namespace

Building generate_building(const BuildingOptions& o) {
  o.validate();
  // The largest grid whose junctions and corridors fit, then rooms (with their doors) to the count.
  int k = 2;
  auto base = [](int g) { return g * g + 2 * g * (g - 1); };
  while (base(k + 1) <= o.nodes) ++k;
  const int blocks = (k - 1) * (k - 1);
  const int rooms = o.rooms ? std::min(blocks, (o.nodes - base(k)) / 2) : 0;
  const double S = o.block_m, z = o.ceiling_m;
  Writer w;
  Building b;
  auto J = [](int i, int j) { return "J" + std::to_string(i) + "_" + std::to_string(j); };
  auto H = [](int i, int j) { return "H" + std::to_string(i) + "_" + std::to_string(j); };
  auto V = [](int i, int j) { return "V" + std::to_string(i) + "_" + std::to_string(j); };
  // Which blocks have a room: a seeded shuffle, so sizes between grids spread them out.
  std::vector<int> order(blocks);
  for (int q = 0; q < blocks; ++q) order[q] = q;
  std::mt19937_64 rng(o.seed);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<char> has_room(blocks, 0);
  for (int r = 0; r < rooms; ++r) has_room[order[r]] = 1;
  // Missing corridors: seeded, never one with a room's door, never one whose loss disconnects
  // the grid (a spanning tree of the junctions is kept whole).
  std::set<std::string> missing;
  {
    std::vector<std::pair<std::string, std::pair<int, int>>> all;  // corridor, its junctions
    auto id = [k](int i, int j) { return i * k + j; };
    for (int i = 0; i + 1 < k; ++i)
      for (int j = 0; j < k; ++j)
        if (!(j + 1 < k && has_room[i * (k - 1) + j]))
          all.push_back({H(i, j), {id(i, j), id(i + 1, j)}});
    for (int i = 0; i < k; ++i)
      for (int j = 0; j + 1 < k; ++j) all.push_back({V(i, j), {id(i, j), id(i, j + 1)}});
    std::shuffle(all.begin(), all.end(), rng);
    int left = o.missing_corridors;
    for (std::size_t c = 0; c < all.size() && left > 0; ++c) {
      // Connected without it (and without those already left out)?
      std::vector<std::vector<int>> adj(k * k);
      for (std::size_t d = 0; d < all.size(); ++d) {
        if (d == c || missing.count(all[d].first)) continue;
        adj[all[d].second.first].push_back(all[d].second.second);
        adj[all[d].second.second].push_back(all[d].second.first);
      }
      std::vector<char> seen(k * k, 0);
      std::vector<int> stack{0};
      seen[0] = 1;
      int reached = 1;
      while (!stack.empty()) {
        const int u = stack.back();
        stack.pop_back();
        for (int v : adj[u])
          if (!seen[v]) {
            seen[v] = 1;
            ++reached;
            stack.push_back(v);
          }
      }
      if (reached < k * k) continue;
      missing.insert(all[c].first);
      --left;
    }
  }
  b.missing.assign(missing.begin(), missing.end());
  // A corridor's lamp (or a junction's) at (x, y) along `yaw`: one, or two across it.
  auto row_lamps = [&](Json& props, const std::string& id, double x, double y, double yaw) {
    if (o.rows == 1) return w.lamp(props, id, x, y, z, yaw, false);
    const double h = 0.5 * o.row_spacing_m;
    w.lamp(props, id + "a", x - h * std::sin(yaw), y + h * std::cos(yaw), z, yaw, false);
    w.lamp(props, id + "b", x + h * std::sin(yaw), y - h * std::cos(yaw), z, yaw, false);
  };
  // Junctions: a corner where two corridors meet at a right angle, a junction where more do.
  auto exits = [&](int i, int j) {
    int n = 0;
    if (i > 0 && !missing.count(H(i - 1, j))) ++n;
    if (i + 1 < k && !missing.count(H(i, j))) ++n;
    if (j > 0 && !missing.count(V(i, j - 1))) ++n;
    if (j + 1 < k && !missing.count(V(i, j))) ++n;
    return n;
  };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const int n = exits(i, j) + (o.lobby && i == 0 && j == 0 ? 1 : 0);
      const bool straight =
          n == 2 &&
          ((i > 0 && i + 1 < k && !missing.count(H(i - 1, j)) && !missing.count(H(i, j))) ||
           (j > 0 && j + 1 < k && !missing.count(V(i, j - 1)) && !missing.count(V(i, j))));
      const char* place = n <= 1 ? "end" : n == 2 && !straight ? "corner" : "junction";
      const double x = i * S, y = j * S;
      Json& props = w.node(J(i, j), place, x, y, Writer::region(x - 1, y - 1, x + 1, y + 1));
      row_lamps(props, J(i, j) + "-L1", x, y, 0.0);
    }
  auto corridor = [&](const std::string& name, double x0, double y0, double x1, double y1,
                      bool room_door) {
    const bool horizontal = y0 == y1;
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    Json& props = w.node(name, "corridor", cx, cy,
                         horizontal ? Writer::region(x0, y0 - 1, x1, y0 + 1)
                                    : Writer::region(x0 - 1, y0, x0 + 1, y1));
    props["metadata"]["axis"] = {{"x_values", {x0, x1}}, {"y_values", {y0, y1}}};
    props["metadata"]["width"] = 2.0;
    const double len = std::hypot(x1 - x0, y1 - y0);
    const bool wing = o.wing_lamp_spacing_m > 0 && std::min(x0, x1) >= 0.5 * (k - 1) * S;
    const double spacing = wing ? o.wing_lamp_spacing_m : o.lamp_spacing_m;
    const int n = static_cast<int>(std::floor(len / spacing));
    const double first = 0.5 * (len - (n - 1) * spacing);
    for (int q = 0; q < n; ++q) {
      const double s = first + q * spacing;
      row_lamps(props, name + "-L" + std::to_string(q + 1), horizontal ? x0 + s : x0,
                horizontal ? y0 : y0 + s, horizontal ? 0.0 : M_PI / 2);
    }
    if (room_door)
      props["lampnav"]["doors"] =
          Json::array({{{"name", "D" + name}, {"side", "left"}, {"at", 0.5 * len}}});
  };
  for (int i = 0; i + 1 < k; ++i)
    for (int j = 0; j < k; ++j) {
      if (missing.count(H(i, j))) continue;
      const bool room = j + 1 < k && has_room[i * (k - 1) + j];
      corridor(H(i, j), i * S + 1, j * S, (i + 1) * S - 1, j * S, room);
      w.link(J(i, j), H(i, j));
      w.link(H(i, j), J(i + 1, j));
      if (!room) continue;
      // The room north of the corridor (its left, going east), through a door at its middle.
      const double x = (i + 0.5) * S, y = j * S;
      w.node("D" + H(i, j), "door", x, y + 1.15, Writer::region(x - 0.5, y + 1, x + 0.5, y + 1.3));
      const std::string room_name = "R" + std::to_string(i) + "_" + std::to_string(j);
      const double rx0 = i * S + 2, rx1 = (i + 1) * S - 2, ry0 = y + 1.3, ry1 = y + 0.5 * S;
      Json& props = w.node(room_name, "room", 0.5 * (rx0 + rx1), 0.5 * (ry0 + ry1),
                           Writer::region(rx0, ry0, rx1, ry1));
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c)
          w.lamp(props, room_name + "-L" + std::to_string(4 * a + c + 1),
                 rx0 + (a + 0.5) * (rx1 - rx0) / 4, ry0 + (c + 0.5) * (ry1 - ry0) / 4, z, 0.0,
                 true);
      w.link(H(i, j), "D" + H(i, j));
      w.link("D" + H(i, j), room_name);
    }
  for (int i = 0; i < k; ++i)
    for (int j = 0; j + 1 < k; ++j) {
      if (missing.count(V(i, j))) continue;
      corridor(V(i, j), i * S, j * S + 1, i * S, (j + 1) * S - 1, false);
      w.link(J(i, j), V(i, j));
      w.link(V(i, j), J(i, j + 1));
    }
  if (o.lobby) {
    // A 10 x 8 m hall west of the origin's corner, entered from it, with round lamps in a grid.
    const double x0 = -11, x1 = -1, y0 = -4, y1 = 4;
    Json& props =
        w.node("Lobby", "hall", 0.5 * (x0 + x1), 0.5 * (y0 + y1), Writer::region(x0, y0, x1, y1));
    int q = 0;
    for (double x = x0 + 1.25; x < x1; x += 2.5)
      for (double y = y0 + 2; y < y1; y += 2.0)
        w.lamp(props, "Lobby-L" + std::to_string(++q), x, y, z, 0.0, true);
    w.link("Lobby", J(0, 0));
  }
  b.grid = k;
  b.nodes = static_cast<int>(w.ids.size());
  b.edges = w.edges;
  b.lamps = w.lamps;
  Json doc = {{"type", "FeatureCollection"},
              {"name", "generated-" + std::to_string(b.nodes)},
              {"lampnav", {{"format", 2}, {"units", "m"}, {"frame", "map"}}},
              {"features", std::move(w.features)}};
  b.geojson = doc.dump();
  return b;
}

}  // namespace lampnav::sim
