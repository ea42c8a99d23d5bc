#pragma once
// The rigid motion (rotation and translation, no scale), or the similarity, that best maps one set
// of 2-D points onto another in the least-squares sense: to put a drive's lamps onto a map's
// (survey), and to compare a built map with the truth (tests).

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::mapping {

// pairs: (point, its counterpart). The result maps a point onto its counterpart:
// counterpart = fit.transform_from(point). Identity for no pairs.
Pose2 fit_rigid(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs);

// A rigid motion after a scale: counterpart = motion.transform_from(scale * point).
struct Similarity {
  Pose2 motion;
  double scale = 1;
  Eigen::Vector2d transform_from(const Eigen::Vector2d& p) const {
    return motion.transform_from(scale * p);
  }
};

// The similarity that best maps the points onto their counterparts (least squares). Identity for
// no pairs; scale 1 when the points are all at one place.
Similarity fit_similarity(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs);

}  // namespace lampnav::mapping
