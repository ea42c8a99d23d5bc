#pragma once
// The Domus museum hall of paper 1 (maps/domus_museum.geojson) and the Pioneer robot that drives
// it (maps/robots/pioneer.json), as the tests of the omni camera load them, and clean omni views
// of a map. Header only, for the test binaries that link sim and vision.

#include <random>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/omni_detector.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

struct Museum {
  std::string geojson = slurp(source_path("maps/domus_museum.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "domus_museum.geojson").map;
  RobotDescription robot = read_robot_description(source_path("maps/robots/pioneer.json"));
  const CameraDescription& omni_camera() const { return *robot.find_camera("omni_camera"); }
  std::vector<const graph::Lamp*> lamps() const {
    std::vector<const graph::Lamp*> out;
    for (const auto& n : map.nodes())
      for (const auto& l : n.lamps) out.push_back(&l);
    return out;
  }
};

// An omni renderer that draws every lamp: nobody in the way, no spurious light.
inline sim::OmniRenderer clean_omni_renderer(const CameraDescription& cam) {
  sim::OmniRenderOptions ro;
  ro.occlusion_probability = 0;
  ro.spurious_per_image = 0;
  return sim::OmniRenderer(cam, ro);
}

// What the omni detector finds in a clean view of every lamp of `map` from `pose`.
inline vision::OmniDetection clean_omni_view(const CameraDescription& cam,
                                             const graph::TopologicalMap& map, const Pose2& pose,
                                             std::uint64_t seed) {
  std::vector<const graph::Lamp*> lamps;
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps) lamps.push_back(&l);
  std::mt19937_64 rng(seed);
  const Image8 img = clean_omni_renderer(cam).render(pose, {}, lamps, rng);
  return vision::OmniLampDetector(cam).detect(vision::ImageView::of(img));
}

}  // namespace lampnav::test
