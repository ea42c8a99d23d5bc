#pragma once
// Checks of a map beyond its format: places no route reaches, corridors the ceiling camera can
// localize in poorly, and lamp spacing a camera could miss at a given speed (paper 2, section 1:
// "each lamp met by the robot on its path [must appear] at least in one webcam image").

#include <functional>
#include <optional>
#include <vector>

#include "lampnav/graph/geojson.hpp"

namespace lampnav::graph {

// The maximum speed (m/s) at which a ceiling camera still sees every lamp whole in at least one
// frame and can still tell consecutive identical lamps apart by their motion between frames:
//   v_max = frame_rate * min(view_length - lamp_extent, spacing / 2)
// view_length: the camera's view along the direction of travel at the lamps' height (m);
// lamp_extent: the lamp's length along that direction (m); spacing: centre distance to the next
// lamp (m, infinity when there is none); frame_rate in Hz. Zero when the lamp does not fit.
double max_speed_every_lamp_seen(double view_length, double lamp_extent, double spacing,
                                 double frame_rate);

// What the ceiling camera sees, for the coverage check.
struct CeilingCoverage {
  // View length (m) along the robot's forward direction at a lamp height z above the floor (m).
  std::function<double(double lamp_height)> view_length;
  double speed = 0.5;       // m/s, the speed to check for
  double frame_rate = 1.0;  // Hz, frames the camera delivers per second
};

struct MapCheckOptions {
  std::optional<CeilingCoverage> coverage;  // the camera check runs only when given
};

// Lamps the ceiling camera could miss or confuse at the coverage's speed and frame rate: one
// warning per corridor, at its limiting lamp.
std::vector<MapWarning> check_camera_coverage(const TopologicalMap& map,
                                              const CeilingCoverage& coverage,
                                              const std::string& file = {});

// Warnings: a node no edge reaches; nodes some other node cannot reach (the graph is not strongly
// connected); a corridor without lamps; with `coverage`, lamps the camera could miss or confuse.
std::vector<MapWarning> check_map(const TopologicalMap& map, const MapCheckOptions& options = {},
                                  const std::string& file = {});

}  // namespace lampnav::graph
