#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::graph {
namespace {

using ::testing::HasSubstr;

// One fixture file per refusal of map-format.md; each message must name the feature (index and
// id) and the field.
struct Refusal {
  const char* file;
  const char* place;  // the feature, or the place in the file
  const char* field;
  const char* message;
};

class MapRefusalTest : public ::testing::TestWithParam<Refusal> {};

TEST_P(MapRefusalTest, NamesFeatureAndField) {
  const Refusal& r = GetParam();
  const std::string path = test::fixture(std::string("maps/") + r.file + ".geojson");
  std::vector<InputError> problems;
  try {
    read_map(path);
    FAIL() << r.file << " was accepted";
  } catch (const InputErrors& e) {
    problems = e.problems();
  } catch (const InputError& e) {
    problems = {e};
  }
  ASSERT_FALSE(problems.empty());
  // The refusal comes first and stands alone: no knock-on complaints about other features.
  ASSERT_EQ(problems.size(), 1u) << problems[1].what();
  const InputError& p = problems.front();
  EXPECT_EQ(p.where().file, path);
  EXPECT_EQ(p.where().place, r.place) << p.what();
  EXPECT_EQ(p.where().field, r.field) << p.what();
  EXPECT_THAT(p.message(), HasSubstr(r.message));
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, MapRefusalTest,
    ::testing::Values(
        Refusal{"not_json", "line 3, column 17", "", "not valid JSON"},
        Refusal{"not_feature_collection", "", "type", "not a GeoJSON FeatureCollection"},
        Refusal{"unknown_format", "", "lampnav.format", "unknown map format 3"},
        Refusal{"missing_format", "", "lampnav.format", "missing"},
        Refusal{"duplicate_id", "features[3] (id 1)", "properties.id", "duplicate id 1"},
        Refusal{"duplicate_name", "features[1] (id 2)", "properties.metadata.name",
                "duplicate name 'C1'"},
        Refusal{"duplicate_lamp_id", "features[0] (id 1)", "properties.lampnav.lamps[1].id",
                "duplicate lamp id"},
        Refusal{"dangling_edge", "features[3] (id 11)", "properties.endid", "names no node (99)"},
        Refusal{"unknown_place", "features[1] (id 2)", "properties.metadata.place",
                "unknown place 'hallway'"},
        Refusal{"missing_coordinate", "features[1] (id 2)", "geometry.coordinates",
                "expected 2 elements"},
        Refusal{"null_coordinate", "features[1] (id 2)", "geometry.coordinates[1]",
                "expected a number"},
        Refusal{"nonfinite_coordinate", "line 97, column 6", "", "not a finite number"},
        Refusal{"lamp_outside_region", "features[0] (id 1)", "properties.lampnav.lamps[1].xyz",
                "outside its node's region"},
        Refusal{"lamp_below_floor", "features[0] (id 1)", "properties.lampnav.lamps[0].xyz",
                "above the floor"},
        Refusal{"region_too_few_vertices", "features[1] (id 2)", "properties.metadata.region",
                "fewer than 3 vertices"},
        Refusal{"region_self_intersecting", "features[1] (id 2)", "properties.metadata.region",
                "self-intersecting"},
        Refusal{"region_zero_area", "features[1] (id 2)", "properties.metadata.region",
                "zero area"},
        Refusal{"overlapping_regions", "features[1] (id 2)", "properties.metadata.region",
                "overlaps the region of 'C1'"},
        Refusal{"unknown_key_metadata", "features[0] (id 1)", "properties.metadata.lamsp",
                "unknown key"},
        Refusal{"unknown_key_lamp", "features[0] (id 1)", "properties.lampnav.lamps[0].colour",
                "unknown key"},
        Refusal{"unknown_key_door", "features[0] (id 1)", "properties.lampnav.doors[0].sdie",
                "unknown key"},
        Refusal{"unknown_key_lampnav", "", "lampnav.unit", "unknown key"},
        Refusal{"nav2_unconvertible_metadata", "features[2] (id 10)",
                "properties.metadata.speed[0]",
                "Nav2's route graph loader cannot convert an array of objects"},
        Refusal{"corridor_without_axis", "features[0] (id 1)", "properties.metadata.axis",
                "missing"},
        Refusal{"bad_lamp_size", "features[0] (id 1)", "properties.lampnav.lamps[0].size",
                "length >= width"}),
    [](const auto& p) { return std::string(p.param.file); });

TEST(MapReader, MissingFileIsNamed) {
  try {
    read_map("/nonexistent/map.geojson");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "/nonexistent/map.geojson");
    EXPECT_THAT(e.message(), HasSubstr("cannot open"));
  }
}

TEST(MapReader, ReportsEveryProblemNotJustTheFirst) {
  const std::string text = R"({"type": "FeatureCollection", "lampnav": {"format": 1}, "features": [
    {"type": "Feature", "geometry": {"type": "Point", "coordinates": [0, 0]},
     "properties": {"id": 1, "metadata": {"name": "A", "place": "attic",
       "region": {"x_values": [0, 1, 1], "y_values": [0, 0, 1]}}}},
    {"type": "Feature", "geometry": {"type": "Point", "coordinates": [5, 5]},
     "properties": {"id": 2, "metadata": {"name": "B", "place": "room", "colour": "red",
       "region": {"x_values": [5, 6, 6], "y_values": [5, 5, 6]}}}}]})";
  try {
    parse_map(text, "two.geojson");
    FAIL();
  } catch (const InputErrors& e) {
    ASSERT_EQ(e.problems().size(), 2u);
    EXPECT_EQ(e.problems()[0].where().place, "features[0] (id 1)");
    EXPECT_EQ(e.problems()[1].where().place, "features[1] (id 2)");
    EXPECT_THAT(std::string(e.what()), HasSubstr("and 1 more problem"));
  }
}

TEST(MapReader, WarnsButAccepts) {
  const LoadedMap lm = read_map(test::fixture("maps/warnings_unreached_and_dark.geojson"));
  ASSERT_EQ(lm.warnings.size(), 2u);
  std::string all;
  for (const auto& w : lm.warnings) all += w.text() + "\n";
  EXPECT_THAT(all, HasSubstr("node 'Lonely' (id 3): no edge reaches this node"));
  EXPECT_THAT(all, HasSubstr("node 'C1' (id 1): properties.lampnav.lamps: corridor without lamps"));
}

TEST(MapReader, EdgeCostDefaultsToGeometricLength) {
  const LoadedMap lm = read_map(test::fixture("maps/valid_tiny.geojson"));
  const Edge* e = lm.map.find_edge(EdgeId(10));
  ASSERT_NE(e, nullptr);
  EXPECT_FALSE(e->cost_given);
  EXPECT_DOUBLE_EQ(e->cost, 6.0);
}

class RoundTrip : public ::testing::TestWithParam<const char*> {};

// Writer output reads back into an identical map, and writing that again gives the same bytes.
TEST_P(RoundTrip, WriteReadIsIdentity) {
  const LoadedMap first = read_map(test::source_path(GetParam()));
  const std::string text = write_map(first.map);
  const LoadedMap second = parse_map(text, "written");
  EXPECT_EQ(write_map(second.map), text);
  ASSERT_EQ(second.map.node_count(), first.map.node_count());
  ASSERT_EQ(second.map.edge_count(), first.map.edge_count());
  ASSERT_EQ(second.map.lamp_count(), first.map.lamp_count());
  EXPECT_EQ(second.map.name(), first.map.name());
  for (std::size_t i = 0; i < first.map.node_count(); ++i) {
    const Node& a = first.map.node_at_index(i);
    const Node& b = second.map.node_at_index(i);
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.place, b.place);
    EXPECT_EQ(a.point, b.point);
    EXPECT_EQ(a.region.vertices(), b.region.vertices());
    EXPECT_EQ(a.doors.size(), b.doors.size());
    ASSERT_EQ(a.lamps.size(), b.lamps.size());
    for (std::size_t k = 0; k < a.lamps.size(); ++k) {
      EXPECT_EQ(a.lamps[k].id, b.lamps[k].id);
      EXPECT_EQ(a.lamps[k].xyz, b.lamps[k].xyz);
      EXPECT_EQ(a.lamps[k].yaw, b.lamps[k].yaw);
      EXPECT_EQ(a.lamps[k].length, b.lamps[k].length);
    }
  }
  for (std::size_t i = 0; i < first.map.edge_count(); ++i) {
    EXPECT_EQ(first.map.edge_at_index(i).cost, second.map.edge_at_index(i).cost);
    EXPECT_EQ(first.map.edge_at_index(i).geometry, second.map.edge_at_index(i).geometry);
  }
}

INSTANTIATE_TEST_SUITE_P(BundledMaps, RoundTrip,
                         ::testing::Values("maps/office_floor.geojson", "maps/domus_museum.geojson",
                                           "tests/fixtures/maps/valid_tiny.geojson",
                                           "tests/fixtures/maps/format1_tiny.geojson"));

}  // namespace
}  // namespace lampnav::graph

namespace lampnav::graph {
namespace {

// Format 1 (map-format.md, replaced by format 2): lamps and doors in metadata, the axis as two
// [x, y] points, a written cost taken as it is. The same map in either format reads the same.
nlohmann::json to_format_1(nlohmann::json doc) {
  doc["lampnav"]["format"] = 1;
  for (auto& f : doc["features"]) {
    auto& props = f["properties"];
    props.erase("overridable");
    if (!props.contains("lampnav")) continue;
    auto& md = props["metadata"];
    for (auto& [k, v] : props["lampnav"].items()) md[k] = v;
    props.erase("lampnav");
    if (md.contains("axis")) {
      const auto a = md["axis"];
      md["axis"] = {{a["x_values"][0], a["y_values"][0]}, {a["x_values"][1], a["y_values"][1]}};
    }
  }
  return doc;
}

TEST(MapReader, ReadsFormat1AsFormat2) {
  for (const char* file : {"maps/office_floor.geojson", "maps/domus_museum.geojson"}) {
    const std::string text = test::slurp(test::source_path(file));
    const TopologicalMap two = parse_map(text, file).map;
    const std::string one_text = to_format_1(nlohmann::json::parse(text)).dump();
    const TopologicalMap one = parse_map(one_text, "format 1").map;
    ASSERT_EQ(one.node_count(), two.node_count()) << file;
    ASSERT_EQ(one.edge_count(), two.edge_count());
    ASSERT_EQ(one.lamp_count(), two.lamp_count());
    EXPECT_GT(two.lamp_count(), 0u);
    for (std::size_t i = 0; i < one.node_count(); ++i) {
      const Node &a = one.node_at_index(i), &b = two.node_at_index(i);
      EXPECT_EQ(a.name, b.name);
      ASSERT_EQ(a.axis.has_value(), b.axis.has_value()) << a.name;
      if (a.axis) {
        EXPECT_EQ(a.axis->first, b.axis->first);
        EXPECT_EQ(a.axis->second, b.axis->second);
      }
      ASSERT_EQ(a.lamps.size(), b.lamps.size()) << a.name;
      for (std::size_t k = 0; k < a.lamps.size(); ++k) {
        EXPECT_EQ(a.lamps[k].id, b.lamps[k].id);
        EXPECT_EQ(a.lamps[k].xyz, b.lamps[k].xyz);
      }
      EXPECT_EQ(a.doors.size(), b.doors.size()) << a.name;
    }
    // Format 1 costs an edge without a cost by its polyline; format 2 by the straight line, so
    // the bundled maps write the polyline's length where it differs. Planning is the same.
    for (std::size_t i = 0; i < one.edge_count(); ++i)
      EXPECT_NEAR(one.edge_at_index(i).cost, two.edge_at_index(i).cost, 2e-4) << i;
  }
}

TEST(MapReader, Format2RefusesLampsInMetadata) {
  const std::string text = test::slurp(test::source_path("maps/office_floor.geojson"));
  nlohmann::json doc = to_format_1(nlohmann::json::parse(text));
  doc["lampnav"]["format"] = 2;  // lamps in metadata, where Nav2's loader throws
  try {
    parse_map(doc.dump(), "m.geojson");
    FAIL() << "accepted";
  } catch (const InputErrors& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("lamps"));
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("lamps"));
  }
}

// A format-1 map is written back in format 2 with its edge costs kept for Nav2: a polyline's
// length where it is not the straight line, with "overridable": false.
TEST(MapWriter, WritesFormat2FromFormat1) {
  const LoadedMap one = read_map(test::fixture("maps/format1_tiny.geojson"));
  const nlohmann::json doc = nlohmann::json::parse(write_map(one.map));
  EXPECT_EQ(doc["lampnav"]["format"], 2);
  for (const auto& f : doc["features"]) {
    const auto& props = f["properties"];
    if (f["geometry"]["type"] == "Point") {
      EXPECT_FALSE(props["metadata"].contains("lamps"));
      EXPECT_TRUE(props.contains("lampnav"));
      if (props["metadata"].contains("axis")) {
        EXPECT_TRUE(props["metadata"]["axis"].is_object());
      }
    } else if (props.contains("cost")) {
      EXPECT_EQ(props["overridable"], false);
    }
  }
  const LoadedMap two = parse_map(doc.dump(), "written");
  for (std::size_t i = 0; i < one.map.edge_count(); ++i)
    EXPECT_DOUBLE_EQ(one.map.edge_at_index(i).cost, two.map.edge_at_index(i).cost);
}

TEST(MapReader, RefusesWhatNav2CannotLoad) {
  const std::string text = test::slurp(test::fixture("maps/valid_tiny.geojson"));
  struct Case {
    const char* what;
    std::function<void(nlohmann::json&)> change;
    const char* field;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"negative id", [](auto& d) { d["features"].back()["properties"]["id"] = -1; },
       "properties.id", "unsigned 32-bit"},
      {"id past 32 bits", [](auto& d) { d["features"].back()["properties"]["id"] = 5000000000LL; },
       "properties.id", "unsigned 32-bit"},
      {"no edges",
       [](auto& d) {
         auto& fs = d["features"];
         for (std::size_t i = fs.size(); i-- > 0;)
           if (fs[i]["geometry"]["type"] != "Point") fs.erase(i);
       },
       "features", "at least one node and one edge"},
      {"not overridable, no cost",
       [](auto& d) { d["features"].back()["properties"]["overridable"] = false; }, "properties",
       "needs a positive cost"},
      {"unknown trigger",
       [](auto& d) {
         d["features"][0]["properties"]["operations"] = {
             {"stop", {{"type", "stop"}, {"trigger", "ON_ARRIVAL"}}}};
       },
       "properties.operations.stop.trigger", "unknown trigger"},
  };
  for (const auto& c : cases) {
    nlohmann::json doc = nlohmann::json::parse(text);
    c.change(doc);
    try {
      parse_map(doc.dump(), "m.geojson");
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const InputErrors& e) {
      ASSERT_EQ(e.problems().size(), 1u) << c.what << ": " << e.what();
      EXPECT_THAT(e.problems()[0].where().field, HasSubstr(c.field)) << c.what;
      EXPECT_THAT(e.problems()[0].message(), HasSubstr(c.message)) << c.what;
    }
  }
}

}  // namespace
}  // namespace lampnav::graph
