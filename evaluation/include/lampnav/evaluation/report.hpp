#pragma once
// The replay's report: one self-contained HTML page (inline SVG, no script, no outside file) with
// the map and the true, odometry-only and fused trajectories; position and heading error over
// time; the covariance's norm over time (paper 2, Fig. 7); when the robot was lost and
// relocalized; the lamps seen and labelled; the metrics table and the replay's notes.

#include <string>
#include <vector>

#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::evaluation {

struct Figure {
  std::string file;  // e.g. "map.svg"
  std::string title;
  std::string svg;
};

// The report's figures, each a standalone SVG.
std::vector<Figure> report_figures(const ReplayResult& result, const io::MissionLog& log,
                                   const graph::TopologicalMap& map);
// The page, with the figures inline.
std::string report_html(const ReplayResult& result, const io::MissionLog& log,
                        const std::vector<Figure>& figures, const std::string& title);
// Writes DIR/report.html and each figure as DIR/<file>.
void write_report(const ReplayResult& result, const io::MissionLog& log,
                  const graph::TopologicalMap& map, const std::string& title,
                  const std::string& dir);

}  // namespace lampnav::evaluation
