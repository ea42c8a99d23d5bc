#pragma once
// What nav2_route's GeoJSON loader can read (navigation2, nav2_route/src/plugins/
// graph_file_loaders/geojson_graph_file_loader.cpp), as checks on lampnav's strict JSON cursor. A
// map that passes them loads in the Nav2 Route Server; one that does not would make it fail to
// configure. Private to the graph module.

#include <cstdint>

#include "lampnav/internal/json_util.hpp"

namespace lampnav::graph::nav2 {

// Nav2 converts `metadata` to values only when each member is a number, a boolean, a string, an
// object of such members (recursively), or an array of numbers, booleans or strings. Anything
// else (an array of objects or of arrays, null) makes the loader throw; this refuses it, naming
// the member.
void check_metadata(const json::Cursor& metadata);

// `operations`: an object (or array) of operations, each with a string `type`, a `trigger` of
// NODE, ON_ENTER or ON_EXIT (Nav2 would silently read any other as NODE) and optional metadata.
void check_operations(const json::Cursor& operations);

// A feature id, start id or end id: Nav2 reads them as unsigned 32-bit integers.
std::int64_t id(const json::Cursor& c);

}  // namespace lampnav::graph::nav2
