#pragma once
// Lamp detection in ceiling-camera frames (paper 2, section 3.2): luminance threshold, connected
// components, an area filter derived from the camera and the lamps, erosion and dilation against
// the fringes of the metallic grid, centre of gravity and orientation from second-order moments,
// and completion of lamps cut by the image border from their known shape.
//
// Moments are taken in UNDISTORTED normalized coordinates (X/Z, Y/Z), each pixel weighted by the
// area it covers there: with a horizontal ceiling in front of an upward camera the lamp's image is
// then an exact scaled copy of the lamp, so its centroid is the image of the lamp's centre. (A
// centroid taken in distorted pixels is pulled towards the image centre by barrel distortion.)

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/vision/image_view.hpp"

namespace lampnav::vision {

// What a lamp looks like from the camera: the emitting face and its distance above the camera's
// optical centre. A map with lamps at several heights gives the range.
struct LampShapePrior {
  bool rectangle = true;          // rectangle (length x width), or disc (diameter = length)
  double length = 1.2;            // m, long side or diameter
  double width = 0.3;             // m, short side (= length for a disc)
  double min_distance = 2.4;      // m, nearest lamp face above the camera
  double max_distance = 2.4;      // m, farthest
  double nominal_distance = 2.4;  // m, used to complete cut lamps
  void validate() const;          // throws InputError naming the field
};

struct LampDetectorOptions {
  int threshold = 128;                 // grey level (8-bit) a lamp pixel reaches
  double min_area_fraction = 0.5;      // of the smallest expected area (paper 2: 3500 of 6300 px)
  double max_area_fraction = 1.6;      // of the largest expected area
  double complete_min_fraction = 0.6;  // cut lamps this visible are completed (paper 2: 4000/6300)
  int opening_radius = 1;              // px, half size of the erosion/dilation square; 0: none
  double max_shape_error = 0.3;        // relative error of a full lamp's axes against the prior
  double max_fit_rms_px = 1.5;         // px, completion fit refused above this edge residual
  void validate() const;               // throws InputError naming the field
};

enum class LampView {
  full,       // wholly inside the image
  completed,  // cut by the border; centre and orientation recovered from the known shape
  partial,    // cut and too little visible to complete: centroid of the visible part only
};
const char* to_string(LampView view);

struct LampDetection {
  LampView view = LampView::full;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();     // undistorted normalized (X/Z, Y/Z)
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  // where that centre appears, in pixels
  double orientation = 0;  // rad in (-pi/2, pi/2]: long axis in the normalized plane, +x to +y
  double length = 0, width = 0;  // normalized units, from the moments (the prior's, if completed)
  double area = 0;               // normalized units^2, visible (after the opening)
  double visible_fraction = 0;   // visible area / the area a whole lamp would have
  int pixels = 0;                // visible pixel count
  std::array<int, 4> bbox{};     // u_min, v_min, u_max, v_max (inclusive)
  std::array<int, 2> seed{};     // a pixel (u, v) of the visible lamp, near its middle
  int fit_points = 0;            // completion: edge points in the fit
  double fit_rms_px = 0;         // completion: rms edge residual, in pixels
};

// Why blobs were not reported as lamps: counters of one frame.
struct DetectionStats {
  int blobs = 0;              // connected components above the threshold
  int too_small = 0;          // including specks of noise and fringe
  int too_large = 0;          // merged lamps, a saturated frame
  int wrong_shape = 0;        // full blobs whose axes do not match the prior
  int completion_failed = 0;  // cut lamps whose edges did not fit the shape (reported partial)
};

struct LampDetections {
  std::vector<LampDetection> lamps;
  DetectionStats stats;  // of the pixels read: the frame, or the windows
  // Bright blobs cut by the image border that are not lamps (yet): a lamp entering the view
  // before enough of it shows, or leaving it. Their bounding boxes, for a tracker to watch.
  std::vector<PixelBox> border_blobs;
  // detect_in only: a blob reached a window's edge inside the image, so it may be larger than
  // the window showed; the lamps of the windows are then incomplete (read the whole frame).
  bool spilled = false;
  long pixels_read = 0;  // pixels thresholded: the frame's, or the windows'
};

class LampDetector {
 public:
  // Throws lampnav::Error when `camera` is not a pinhole camera, InputError for bad options.
  LampDetector(const CameraDescription& camera, const LampShapePrior& prior,
               const LampDetectorOptions& options = {});
  ~LampDetector();
  LampDetector(LampDetector&&) noexcept;
  LampDetector& operator=(LampDetector&&) noexcept;

  // Detects the lamps of one frame. The image must have the camera's size (see check_image);
  // colour and 16-bit frames are converted to 8-bit luminance. Not thread-safe: it reuses buffers.
  LampDetections detect(const ImageView& image);
  LampDetections detect(const Image8& image) { return detect(ImageView::of(image)); }
  // The same, reading only the pixels of `windows` (overlapping ones are merged; each is clipped
  // to the image). A blob wholly inside a window is measured exactly as detect() measures it:
  // same component, same moments, completion from the same grey levels.
  LampDetections detect_in(const ImageView& image, std::vector<PixelBox> windows);

  // Expected normalized area of a whole lamp at the nominal distance.
  double expected_area() const;
  // A lower bound on the pixels of the image's left or right column that a blob reported as a
  // lamp covers when the column cuts it: a tracker may read those columns this many pixels apart
  // and still see every lamp entering there (see LampTracker).
  double border_chord_px() const;
  const LampShapePrior& prior() const;
  const LampDetectorOptions& options() const;
  int width() const;
  int height() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::vision
