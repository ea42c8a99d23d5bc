#pragma once
// Paper 1, IV-A: the ceiling map projection (Alg. 1) and the merit function (Alg. 2, Eq. 5) that
// scores a pose by how well the lamps it predicts land on the lamps detected in one
// omnidirectional image. Both run thousands of times per image, so the projection uses a radial
// table of the fisheye model instead of its trigonometry, and the detections sit in a grid.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion {

// Alg. 1: the image of every map lamp seen from a robot pose on a level floor (B^C = R_C (B^W -
// C^W), then the Pajdla-Bakstein model, Eqs. 1-2), with the camera mount of robot.json.
class CeilingMapProjection {
 public:
  // Throws Error when the camera is not a fisheye one (pajdla_bakstein, kannala_brandt).
  CeilingMapProjection(const graph::TopologicalMap& map, const CameraDescription& omni_camera);

  // The pixels of the lamps inside the field of view and the image; `lamp` (if given) receives
  // the index into lamps() of each. Both vectors are cleared first.
  void project(const Pose2& robot, std::vector<Eigen::Vector2d>& pixels,
               std::vector<int>* lamp = nullptr) const;
  const std::vector<const graph::Lamp*>& lamps() const { return lamps_; }

 private:
  std::vector<const graph::Lamp*> lamps_;
  // Lamp centres in single precision, relative to the lamps' mean (a map far from its origin
  // keeps its precision: a float 5,000 km out is 0.5 m from the next).
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::vector<float> lx_, ly_, lz_;
  Eigen::Matrix3d mount_Rt_;  // base -> camera
  Eigen::Vector3d mount_t_;
  double u0_, v0_, beta_;
  int width_, height_;
  // r / t as a function of s = t^2, t = tan(theta / 2): smooth up to the edge of the view.
  std::vector<float> g_table_;
  double t_max_, s_max_, s_step_inv_;
};

struct Merit {
  int matched = 0;      // N_P
  double error_px = 0;  // epsilon_P: matched distances, plus the threshold per unmatched detection
  double value = std::numeric_limits<double>::infinity();  // M(P) = epsilon_P / N_P
};

// Alg. 2 and Eq. 5 against one image's detections. A detection j and a projected lamp i match
// when (1) they are closer than the threshold, (2) j is the detection nearest to i, and (3) no
// other lamp claims j more closely (one-to-one). Each detection adds its distance when matched
// and the threshold when not; M(P) is that sum over the number matched (infinite for none).
class MeritFunction {
 public:
  MeritFunction(std::vector<Eigen::Vector2d> detected_px, double threshold_px, int width,
                int height);
  // `matches` (if given) receives (projection index, detection index) pairs.
  Merit operator()(const std::vector<Eigen::Vector2d>& projected,
                   std::vector<std::pair<int, int>>* matches = nullptr) const;

  std::size_t detections() const { return detected_.size(); }

 private:
  std::vector<Eigen::Vector2d> detected_;
  double threshold_;
  // A 16 px grid over the image; each cell lists the detections closer than the threshold to
  // some point of it, so a projection reads one cell (almost always empty or one detection).
  int cols_, rows_;
  std::vector<int> cell_start_, cell_items_;
  void claim(double x, double y, int i) const;
  Merit tally(std::vector<std::pair<int, int>>* matches) const;
  mutable std::vector<double> claim_d2_;
  mutable std::vector<int> claim_by_;
};

}  // namespace lampnav::fusion
