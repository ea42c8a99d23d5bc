#pragma once
// Lamps in the IR-filtered omnidirectional image (paper 1, III-D): every lamp is a saturated blob
// on a dark background. Threshold, bright blobs (connected components), and per blob its pixel
// count, perimeter, centroid, radius from the image centre and azimuth, plus the ray it sees. A
// big blob (lamps right above the camera bloom together, paper 1 Fig. 9) is labelled again with
// a higher threshold that separates the lamps inside it. Spurious lights and hidden lamps are the
// normal case: this stage reports blobs, the matching decides what they are.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/vision/image_view.hpp"

namespace lampnav::vision {

struct OmniDetectorOptions {
  int threshold = 128;          // grey level of a lamp pixel
  int bloom_threshold = 240;    // the second threshold for big blobs
  int min_pixels = 3;           // smaller blobs are noise
  int big_blob_pixels = 400;    // blobs larger than this are re-labelled at bloom_threshold
  int max_blobs = 256;          // beyond this the frame is refused as a flood of specks
  double max_theta_deg = 92.0;  // blobs further off-axis are ignored (horizon clutter)
  void validate() const;        // throws InputError naming the field
};

struct OmniBlob {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  // (u, v), pixel centres at integers
  int pixels = 0;
  int perimeter = 0;     // blob pixels with a 4-neighbour outside the blob
  double radius_px = 0;  // from the projection centre (u0, v0)
  double azimuth = 0;    // rad, atan2 of (v - v0) / beta and (u - u0), as the fisheye's phi
  double theta = 0;      // rad off the optical axis
  Eigen::Vector3d ray = Eigen::Vector3d::UnitZ();  // unit direction in the camera frame
  double angular_radius = 0;  // rad, the radius of a disc of its area, seen from the camera
  bool from_bloom = false;    // split out of a big blob by the second threshold
  // A streak: a blob at least twice as long as it is wide (lamps of a row merged into one
  // bloom, from overhead to the horizon). Its disc of the same area hides most of it, so the
  // directions of the ends of its long axis are kept, sqrt(3) standard deviations of its pixels
  // from the centroid (a uniform streak's ends), and its half width across it (rad).
  bool streak = false;
  Eigen::Vector3d streak_ends[2] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};
  double streak_half_width = 0;
};

struct OmniDetection {
  std::vector<OmniBlob> blobs;
  int raw_blobs = 0;  // components at the first threshold
  int too_small = 0, outside_view = 0, split_blooms = 0;
  bool flooded = false;  // more than max_blobs: nothing reported
};

class OmniLampDetector {
 public:
  // Throws InputError when the camera is not a fisheye one or the options are bad.
  explicit OmniLampDetector(const CameraDescription& camera,
                            const OmniDetectorOptions& options = {});
  ~OmniLampDetector();
  OmniLampDetector(OmniLampDetector&&) noexcept;
  OmniLampDetector& operator=(OmniLampDetector&&) noexcept;

  // Throws InputError for an image that is not one of this camera (size, channels, depth).
  OmniDetection detect(const ImageView& image);
  const OmniDetectorOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::vision
