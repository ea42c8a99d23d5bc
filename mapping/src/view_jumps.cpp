#include "view_jumps.hpp"

#include <cmath>

namespace lampnav::mapping {

namespace {

using vision::LampDetection;

bool well_inside(const LampDetection& d, const CameraDescription& cam, double margin) {
  const double mu = margin * cam.width, mv = margin * cam.height;
  return d.view == vision::LampView::full && d.centre_px.x() >= mu && d.centre_px.y() >= mv &&
         d.centre_px.x() <= cam.width - mu && d.centre_px.y() <= cam.height - mv;
}

// Whether some lamp of `other` lies where `d` could have moved to (or come from) between the
// frames, the robot having travelled `travel` m and turned `turn` rad.
bool has_counterpart(const LampDetection& d, const std::vector<LampDetection>& other, double travel,
                     double turn, const ViewJumpOptions& o) {
  const double gate = o.gate + travel / o.min_height_m + std::abs(turn) * (d.centre.norm() + 0.3);
  for (const LampDetection& e : other)
    if ((e.centre - d.centre).norm() <= gate) return true;
  return false;
}

}  // namespace

std::vector<std::size_t> view_jumps(const std::vector<ViewFrame>& frames,
                                    const CameraDescription& cam, double semi_axis,
                                    const ViewJumpOptions& o) {
  // The frames with lamps, in order.
  std::vector<std::size_t> lit;
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].lamps && !frames[i].lamps->empty()) lit.push_back(i);
  auto motion = [&](std::size_t a, std::size_t b, double& travel, double& turn) {
    const double dl = frames[b].left - frames[a].left, dr = frames[b].right - frames[a].right;
    travel = std::abs(dl + dr) / 2;
    turn = semi_axis > 0 ? (dr - dl) / (2 * semi_axis) : 0.0;
  };
  auto jumped = [&](std::size_t a, std::size_t b) {
    double travel = 0, turn = 0;
    motion(a, b, travel, turn);
    const auto& before = *frames[a].lamps;
    const auto& after = *frames[b].lamps;
    for (const LampDetection& d : before)
      if (has_counterpart(d, after, travel, turn, o)) return false;  // a lamp stayed in view
    for (const LampDetection& d : after)
      if (well_inside(d, cam, o.margin) && !has_counterpart(d, before, travel, turn, o))
        return true;  // and a whole lamp is well inside that was nowhere near before
    return false;
  };
  std::vector<std::size_t> out;
  for (std::size_t k = 1; k + 1 < lit.size(); ++k) {
    if (!jumped(lit[k - 1], lit[k])) continue;
    // The new view holds in the next frame with lamps: not one bad frame.
    if (!jumped(lit[k - 1], lit[k + 1])) continue;
    out.push_back(lit[k]);
  }
  return out;
}

}  // namespace lampnav::mapping
