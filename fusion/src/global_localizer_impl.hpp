#pragma once
// The global localizer's private parts, shared by its sources: global_localizer.cpp (options,
// scoring a pose against the blobs, least squares, ranking, the API), lamp_pairs.cpp (method
// `default`) and paper_method.cpp (method `paper`, Alg. 3).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ceiling_rays.hpp"
#include "flat_grid.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/merit.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {
namespace detail {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kDeg = M_PI / 180.0;

// Distance (a chord, as between unit rays) from p to the segment a-b.
inline double distance_to_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

struct BlobRay {
  Vector3d ray;  // camera frame
  double theta, angular_radius;
  int index;                     // into the detection's blobs
  const vision::OmniBlob* blob;  // its streak's ends and width (vision::OmniBlob)
};

// The blobs of one image by where their rays point, to find those within a chord of a ray
// without trying every blob (a 1,000-node building's view holds about 77 blobs and 95 lamps). Rays
// are binned by their x and y, which no chord is shorter than. Blobs of more than kSmall rad
// (a lamp nearly overhead) are few and wide: they are tried for every ray, so that a query's
// reach needs to allow only for the largest small blob.
class RayGrid {
 public:
  static constexpr double kSmall = 0.06;
  // Up to kFew blobs are all tried for every ray, unbinned: the screening's cone holds about 5.
  static constexpr std::size_t kFew = 12;
  // Bins the blobs (the storage of an earlier build kept).
  void build(const std::vector<BlobRay>& blobs) {
    wide_.clear();
    index_.clear();
    largest_term_ = 0;
    if (blobs.size() <= kFew) {
      for (std::size_t j = 0; j < blobs.size(); ++j) wide_.push_back(static_cast<int>(j));
      return;
    }
    cell_of_.assign(blobs.size(), -1);
    start_.assign(kCells * kCells + 1, 0);
    for (std::size_t j = 0; j < blobs.size(); ++j) {
      if (blobs[j].angular_radius > kSmall) {
        wide_.push_back(static_cast<int>(j));
        continue;
      }
      largest_term_ =
          std::max(largest_term_, 0.25 * blobs[j].angular_radius * blobs[j].angular_radius);
      cell_of_[j] = bin(blobs[j].ray.y()) * kCells + bin(blobs[j].ray.x());
      ++start_[cell_of_[j] + 1];
    }
    for (int c = 0; c < kCells * kCells; ++c) start_[c + 1] += start_[c];
    index_.resize(blobs.size() - wide_.size());
    next_.assign(start_.begin(), start_.end() - 1);
    for (std::size_t j = 0; j < blobs.size(); ++j)
      if (cell_of_[j] >= 0) index_[next_[cell_of_[j]]++] = static_cast<int>(j);
  }
  // 0.25 times the largest small blob's angular radius, squared: its term in a pair's sigma.
  double largest_term() const { return largest_term_; }
  // Calls f(j) for every wide blob and every small one whose ray's x and y lie within `reach`
  // of `ray`'s (and some more, of the same cells).
  template <class F>
  void visit(const Eigen::Vector3d& ray, double reach, F&& f) const {
    for (const int j : wide_) f(j);
    if (index_.empty()) return;
    const double r = reach + 1e-9;  // a ray on a cell's edge is in both
    const int x0 = bin(ray.x() - r), x1 = bin(ray.x() + r);
    const int y0 = bin(ray.y() - r), y1 = bin(ray.y() + r);
    for (int y = y0; y <= y1; ++y) {
      const int row = y * kCells;
      for (int k = start_[row + x0]; k < start_[row + x1 + 1]; ++k) f(index_[k]);
    }
  }

 private:
  static constexpr int kCells = 24;  // over [-1, 1]: cells of 0.083
  static int bin(double v) {
    const double c = std::floor((v + 1.0) * (0.5 * kCells));
    return static_cast<int>(std::clamp(std::isfinite(c) ? c : 0.0, 0.0, kCells - 1.0));
  }
  std::vector<int> wide_, start_, next_, index_, cell_of_;
  double largest_term_ = 0;
};

// One pose scored against the blobs.
struct Evaluation {
  double cost = std::numeric_limits<double>::infinity();
  int expected = 0, missing = 0, unexplained = 0;  // (itemized or not)
  std::vector<std::pair<int, int>> matches;        // (lamp index, blob index into BlobRay list)
  // What each lamp's directions added to the cost: its match in clear view, the blobs past it
  // it is the nearest lamp of (lamp index, -2 ln L).
  std::vector<std::pair<int, double>> lamp_costs;
  std::vector<int> missed;  // the missing lamps (indices)
  std::vector<int> strays;  // the blobs no lamp explains (BlobRay indices)
};

// The floor's tilt of the base (rad), a nuisance estimated with each pose.
struct Tilt {
  double roll = 0, pitch = 0;
  // body^T without yaw: Rx(-roll) Ry(-pitch), and its derivatives by roll and pitch.
  Matrix3d inverse_rotation() const { return rx() * ry(); }
  std::pair<Matrix3d, Matrix3d> inverse_rotation_derivatives() const {
    const double cr = std::cos(roll), sr = std::sin(roll);
    const double cp = std::cos(pitch), sp = std::sin(pitch);
    Matrix3d dRx, dRy;
    dRx << 0, 0, 0, 0, -sr, cr, 0, -cr, -sr;
    dRy << -sp, 0, -cp, 0, 0, 0, cp, 0, -sp;
    return {dRx * ry(), rx() * dRy};
  }
  Matrix3d rx() const {  // Rx(-roll)
    const double c = std::cos(roll), s = std::sin(roll);
    Matrix3d R;
    R << 1, 0, 0, 0, c, s, 0, -s, c;
    return R;
  }
  Matrix3d ry() const {  // Ry(-pitch)
    const double c = std::cos(pitch), s = std::sin(pitch);
    Matrix3d R;
    R << c, 0, -s, 0, 1, 0, s, 0, c;
    return R;
  }
};

class ParticleRandom;  // paper_method.cpp

inline bool distinct(const Pose2& a, const Pose2& b, double metres, double degrees) {
  return (a.translation() - b.translation()).norm() > metres ||
         std::abs(wrap_angle(a.yaw() - b.yaw())) > degrees * kDeg;
}

}  // namespace detail

struct GlobalLocalizer::Impl {
  using BlobRay = detail::BlobRay;
  using Evaluation = detail::Evaluation;
  using Tilt = detail::Tilt;
  using ParticleRandom = detail::ParticleRandom;
  using Matrix3d = detail::Matrix3d;
  using Vector2d = detail::Vector2d;
  using Vector3d = detail::Vector3d;

  const graph::TopologicalMap* map;
  GlobalLocalizerOptions o;
  vision::FisheyeCamera model;
  CeilingMapProjection projection;
  Matrix3d mount_R, mount_Rt;  // camera -> base, base -> camera
  Vector3d mount_t;
  std::vector<const graph::Lamp*> lamps;
  std::vector<const graph::Node*> regions;  // nodes with a region, for the paper's uniform poses
  std::vector<double> region_cdf;
  bool has_regions = false;

  // Lamps in classes of one height above the camera and one length (5 cm steps): a blob puts
  // every lamp of a class at the same place in the robot's frame.
  struct LampClass {
    double height, length;
  };
  std::vector<LampClass> classes;
  double spurious_limit = 0;  // spurious_blobs.hpp: blobs too small to be a lamp never seed
  std::vector<int> class_of;  // per lamp
  // Ordered pairs of lamps close enough to be seen together as seeds, grouped by their classes
  // and sorted by horizontal distance: a pair of blobs looks up the pairs spaced like it.
  struct LampPair {
    double distance, angle;  // of b from a, horizontal
    int a, b;
  };
  std::vector<std::pair<std::pair<int, int>, std::vector<LampPair>>> pair_groups;
  // The lamps a pose can see (within max_theta): on small maps all of them, on big ones those
  // within view_radius, found in a grid of the lamps' indices (cells in one array, by cell).
  // Scoring a pose asks this thousands of times a frame: it returns the map's lamps in the
  // map's order, as the map's own spatial index would, without its callbacks and pointers.
  std::unordered_map<const graph::Lamp*, int> lamp_index;
  double view_radius = 0;
  double max_height = 0;    // of a lamp above the camera
  double usual_height = 0;  // the median lamp's above the camera
  detail::FlatGrid grid;    // cells of half the view radius
  // Cells of a metre, for the screening's "is there a lamp of this class within r of here?".
  detail::FlatGrid fine_grid;
  std::vector<Vector2d> lamp_xy;                   // per lamp
  std::vector<double> lamp_cos_yaw, lamp_sin_yaw;  // per lamp
  void index_lamps();
  void grid_lamps();
  // Whether a lamp of class `cl` lies within r of p (the map's distance test).
  bool lamp_of_class_within(const Vector2d& p, double r, int cl) const {
    bool found = false;
    fine_grid.visit(p, r, [&](int i) {
      if (!found && class_of[i] == cl && (lamp_xy[i] - p).squaredNorm() <= r * r) found = true;
    });
    return found;
  }
  // The lamps within `radius` of the pose (0: view_radius), in the map's order, into `out`.
  void lamps_in_view(const Pose2& pose, double radius, std::vector<int>& out) const;

  Impl(const graph::TopologicalMap& m, const CameraDescription& camera,
       const GlobalLocalizerOptions& opt);

  const graph::Node* node_of(const Pose2& p) const {
    return map->node_near(p.translation(), o.pairs.graph_margin_m);
  }
  // Hypotheses refined outside every node's region dropped (restrict_to_graph), the rest in order.
  void drop_outside_graph(std::vector<PoseHypothesis>& hs) const {
    if (!o.pairs.restrict_to_graph || !has_regions) return;
    hs.erase(std::remove_if(hs.begin(), hs.end(),
                            [&](const PoseHypothesis& h) { return !node_of(h.pose); }),
             hs.end());
  }
  // Batches of more than `n` costly items go on every core, unless the options say one.
  std::size_t serial_up_to(std::size_t n) const {
    return o.parallel ? n : std::numeric_limits<std::size_t>::max();
  }

  // ---------------------------------------------------------------------------------------
  // Scoring a pose. The lamp in the camera frame from a robot pose, the base tilted by the floor
  // (roll about x, then pitch about y, as conventions.md orders roll-pitch-yaw).
  Vector3d camera_point(const Pose2& pose, const Vector3d& lamp, const Tilt& tilt = {}) const;
  // The same for many lamps from one pose: its sine, cosine and tilt taken once.
  class CameraView {
   public:
    CameraView(const Impl& impl, const Pose2& pose, const Tilt& tilt);
    Vector3d point(const Vector3d& lamp) const;

   private:
    const Impl* impl_;
    Pose2 pose_;
    double c_, s_;
    bool tilted_;
    Matrix3d tilt_inverse_;
  };

  std::vector<BlobRay> blob_rays(const vision::OmniDetection& d, double max_theta) const;
  // Where a blob's `ray` (camera frame) would put a lamp at the usual height, seen from `pose`;
  // none at or below the lamps' horizon.
  std::optional<StraySighting> sighting(const Pose2& pose, const Vector3d& ray) const {
    if (!(usual_height > 0)) return std::nullopt;
    const std::optional<Vector3d> base = detail::ceiling_point(mount_R, mount_t, ray, usual_height);
    if (!base) return std::nullopt;
    const double tilt = o.pairs.tilt_sigma_deg * detail::kDeg, yaw = 1.0 * detail::kDeg;
    const double distance = (*base - mount_t).head<2>().norm(), slant = distance / usual_height;
    StraySighting s;
    s.at = pose.transform_from(base->head<2>());
    s.reach = 3 * (tilt * usual_height * (1 + slant * slant) + yaw * distance);
    return s;
  }
  // Where the blobs no lamp explains would put a lamp at the usual height, seen from `pose`.
  std::vector<StraySighting> stray_sightings(const Pose2& pose, const Evaluation& e,
                                             const std::vector<BlobRay>& blobs) const;

  // A blob's centroid is not quite the projection of the lamp's centre (the lens bends a near
  // lamp's face unevenly): a tenth of the lamp's angular size (rad).
  static double face_sigma(const graph::Lamp& l, double range) { return 0.1 * l.length / range; }
  // Half the angular size (rad) of a lamp's blob seen along `sight` (unit, camera to lamp, in
  // the map) from `range`: the IR bloom makes it larger than the lamp by kBloom.
  static constexpr double kBloom = 0.05;
  double blob_half_size(int lamp, const Vector3d& sight, double range) const;

  // Scores a pose known within (position_sigma, yaw_sigma) and a floor tilt known within
  // tilt_sigma: predicted lamps matched one-to-one to blobs, nearest first, within 3 sigma.
  // With `screen_theta` (rad) only lamps within it of the axis are predicted and expected: a
  // cheaper screening of many candidates with the blobs of that cone. `itemized`: the cost's
  // items too (Evaluation::lamp_costs, strays), for the scores a hypothesis set weighs; the
  // screening and the rounds of least squares, thousands of calls an image, go without.
  Evaluation evaluate(const Pose2& pose, const Tilt& tilt, double position_sigma, double yaw_sigma,
                      double tilt_sigma, const std::vector<BlobRay>& blobs, double screen_theta = 0,
                      bool itemized = false) const;

  struct Solution {
    Pose2 pose;
    Tilt tilt;
    Matrix3d covariance;  // of the pose, the tilt marginalized
    Eigen::Matrix2d tilt_covariance;
    double cost = 0;  // robust sum of squared normalized residuals, plus the tilt's prior
  };

  // Gauss-Newton on the matched lamps: the pose (and the floor's tilt, with its prior) whose
  // predicted directions are nearest the seen ones. Tilt and translation both move the lamps in
  // view, but differently: a tilt turns every ray by the same angle, a translation turns a ray
  // by less the further off-axis its lamp is; the wide view tells them apart.
  // Without `with_tilt` the tilt is held as given (zero: a level floor).
  Solution solve(Pose2 pose, Tilt tilt, const Evaluation& e, const std::vector<BlobRay>& blobs,
                 bool with_tilt) const;
  // N = 5: the pose and the tilt; N = 3: the pose, the tilt held.
  template <int N>
  Solution solve_for(Pose2 pose, Tilt tilt, const Evaluation& e,
                     const std::vector<BlobRay>& blobs) const;

  // Refines a pose: match, solve, match again with the tolerance the solution earned.
  // `rounds` of match-and-solve; `with_tilt`: the floor's tilt estimated too (three times
  // dearer); else the tilt is held at `held` (a level floor, or the image's tilt estimated at
  // another pose: a floor bump tilts the camera alike whatever the pose). `tilt_out`: the
  // tilt of the result.
  PoseHypothesis refine(Pose2 pose, double position_sigma, double yaw_sigma,
                        const std::vector<BlobRay>& blobs, int rounds = 3, bool with_tilt = true,
                        const Tilt& held = {}, Tilt* tilt_out = nullptr) const;

  // The paper's merit of a pose, for every hypothesis whatever its method.
  double paper_merit(const Pose2& pose, const MeritFunction& merit) const;

  MeritFunction merit_function(const vision::OmniDetection& d) const;

  // ---------------------------------------------------------------------------------------
  // Method `default`.

  // The blobs nearest the optical axis (at most `max`), and where each puts a lamp of each
  // class in the base frame, were it one, with the sigma of that place (-1: says nothing).
  struct Seeds {
    std::vector<BlobRay> rays;
    std::vector<Eigen::Vector2d> at;  // [seed * classes + class]
    std::vector<double> sigma;
    std::size_t size() const { return rays.size(); }
  };
  // `oblique`: a seed's sigma allows for a long lamp's centroid off its centre (the
  // enumeration), or the vote's tuned tenth of the lamp's length.
  Seeds seeds_of(const std::vector<BlobRay>& blobs, const LampPairOptions& q, std::size_t max,
                 bool oblique) const;
  // Each pose that puts seeds j and k on a pair of map lamps spaced like them (both classes'
  // index looked up by spacing): fn(pose).
  template <class Fn>
  void pair_poses(const Seeds& s, std::size_t j, std::size_t k, Fn fn) const;
  // With `q` and `max_hypotheses` (the options', or enumerate()'s larger caps).
  GlobalLocalization lamp_pairs(const vision::OmniDetection& d, const LampPairOptions& q,
                                int max_hypotheses) const;

  // Every pose the lamps nearest the optical axis allow (global_localizer.hpp, enumerate()).
  GlobalLocalization exhaustive(const vision::OmniDetection& d, int cap, double margin,
                                const EnumerationPrior* prior) const;

  // Ranks, merges near-duplicates, weighs, places on the graph, and says whether it is ambiguous.
  // `with_merit`: each hypothesis gets the paper's merit too (a projection of the map's lamps
  // per hypothesis); without, merit is NaN.
  void finish(GlobalLocalization& out, std::vector<PoseHypothesis> hs,
              const vision::OmniDetection& d, const LampPairOptions& q, int max_hypotheses,
              bool with_merit) const;

  // ---------------------------------------------------------------------------------------
  // Method `paper` (Alg. 3).
  Pose2 uniform_pose(ParticleRandom& rng) const;

  GlobalLocalization paper(const vision::OmniDetection& d) const;
};

}  // namespace lampnav::fusion
