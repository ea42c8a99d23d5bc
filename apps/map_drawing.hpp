#pragma once
// Draws a map (regions, graph, lamps, doors, names) to PNG or SVG with cairo.

#include <string>

#include "lampnav/graph/map.hpp"

namespace lampnav::apps {

struct DrawingOptions {
  int max_size_px = 1600;  // the longer side of the picture, px
  bool lamp_ids = false;   // label every lamp with its id
};

// Writes `path`; the format follows the extension (.png or .svg). Throws lampnav::InputError
// naming the file when the extension is unknown or the file cannot be written.
void draw_map(const graph::TopologicalMap& map, const std::string& path,
              const DrawingOptions& options = {});

}  // namespace lampnav::apps
