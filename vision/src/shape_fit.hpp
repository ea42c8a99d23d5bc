#pragma once
// Completion's least squares (paper 2: a cut lamp completed "with a least square method"): a
// rectangle or a disc of known size fitted to edge points. Private to lampnav::vision.

#include <Eigen/Core>
#include <vector>

namespace lampnav::vision::detail {

// An edge point of the visible lamp in normalized coordinates.
using EdgePoints = std::vector<Eigen::Vector2d>;

struct ShapeFit {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double orientation = 0;
  double rms = 0;  // normalized units
  int points = 0;
  bool ok = false;
};

// The fit's state per point, kept by the caller from call to call (no allocation once the sizes
// have settled).
struct FitScratch {
  std::vector<char> part;  // each point: in the fit (on which part of the shape) or dropped
  std::vector<int> near;   // a rectangle's points whose part a small move of the shape could change
};

// Gauss-Newton fit of a rectangle (half sizes a >= b, normalized units) or a disc (radius a) of
// known size to edge points, from one initial centre `c` and heading `theta`. Once the fit has
// settled on every point (or after three iterations), points more than max(min_drop, 3 rms) from
// the shape are dropped (fringe, corners), and it goes on until it settles again. A rectangle's
// sums come from moments of its points kept per part of the shape, so an iteration only has to
// find the points that changed part; and it looks only at the points near a change (by a corner,
// or near being dropped), as long as the shape has moved less than their margin since they were
// all looked at. The result is the same as looking at every point every time.
ShapeFit fit_shape(const EdgePoints& pts, bool rectangle, double a, double b, Eigen::Vector2d c,
                   double theta, double min_drop, FitScratch& scratch);

}  // namespace lampnav::vision::detail
