#pragma once
// The camera models of conventions.md. Pixel coordinates: u right, v down, integer values at
// pixel CENTRES (OpenCV's convention).

#include <Eigen/Core>
#include <array>
#include <optional>

#include "lampnav/core/robot_description.hpp"

namespace lampnav::vision {

// Whether a pixel lies in a width x height image (centres 0..W-1, with half a pixel of border).
inline bool in_image(const Eigen::Vector2d& px, int width, int height) {
  return px.x() >= -0.5 && px.y() >= -0.5 && px.x() <= width - 0.5 && px.y() <= height - 0.5;
}

// A central camera seeing less than 90 degrees off its axis, through the normalized plane
// (x, y) = (X/Z, Y/Z) and a distortion of it, then fx, fy, cx, cy; the ceiling camera's models:
//  - `pinhole`: OpenCV's radial-tangential distortion [k1, k2, p1, p2, k3];
//  - `kannala_brandt` (Kalibr's pinhole-equi, OpenCV's cv::fisheye, ROS's equidistant): the
//    distorted point is (x, y) theta_d / r, r = |(x, y)|, theta = atan(r), theta_d = theta (1 +
//    k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8): a wide-angle webcam's lens. Its view
//    ends at fov_deg / 2 off the axis, where theta_d stops growing, or 89 degrees.
class PinholeCamera {
 public:
  // Throws lampnav::Error when the description is neither.
  explicit PinholeCamera(const CameraDescription& description);
  // fx, fy, cx, cy of either model (a Kannala-Brandt camera's fx, fx beta, u0, v0; no
  // radial-tangential distortion).
  static PinholeParameters intrinsics(const CameraDescription& description);
  // Whether a camera of this model can be the ceiling camera (pinhole or kannala_brandt).
  static bool takes(CameraModelKind model);

  int width() const { return width_; }
  int height() const { return height_; }
  const PinholeParameters& parameters() const { return p_; }
  bool equidistant() const { return equidistant_; }

  // Pixel of a camera-frame point; nullopt behind the lens or beyond the radius where the
  // distortion polynomial folds back.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const;
  // Unit ray (Z > 0) through a pixel, undoing the distortion iteratively.
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel) const;
  // Normalized image coordinates (x, y) = (X/Z, Y/Z) -> distorted ones, and back.
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const;
  Eigen::Vector2d undistort(const Eigen::Vector2d& xy_distorted) const;
  // d distort / d (x, y), analytic.
  Eigen::Matrix2d distort_jacobian(const Eigen::Vector2d& xy) const;
  // Pixel -> undistorted normalized coordinates (x, y) = (X/Z, Y/Z), and back.
  Eigen::Vector2d normalized_of_pixel(const Eigen::Vector2d& pixel) const;
  Eigen::Vector2d pixel_of_normalized(const Eigen::Vector2d& xy) const;
  // How far the image reaches in the normalized plane: its farthest corner pixel's |(x, y)|.
  double corner_radius() const;
  // The covariance in the normalized plane, at (x, y), of a pixel error of `pixel_sigma` in
  // each direction: a pixel spans more of the plane where the lens compresses the view (far
  // off the axis of a wide lens).
  Eigen::Matrix2d normalized_covariance(const Eigen::Vector2d& xy, double pixel_sigma) const;
  // d pixel / d (X, Y, Z) of a camera-frame point in front of the lens (analytic).
  Eigen::Matrix<double, 2, 3> project_jacobian(const Eigen::Vector3d& point) const;
  // Whether a pixel lies in the image (pixel centres 0..W-1, 0..H-1, with half a pixel of border).
  bool in_image(const Eigen::Vector2d& pixel) const {
    return vision::in_image(pixel, width_, height_);
  }

 private:
  // Kannala-Brandt: theta_d of theta, its derivative, and theta of theta_d on [0, max_theta_].
  double theta_d(double theta) const;
  double theta_d_derivative(double theta) const;
  double theta_of(double theta_d) const;

  PinholeParameters p_;
  int width_, height_;
  double max_r2_;              // normalized radius^2 where the distortion stops growing
  bool equidistant_ = false;   // Kannala-Brandt
  std::array<double, 4> k_{};  // its k1 .. k4
  double max_theta_ = 0;       // its view's edge off the axis (rad)
};

// The fisheye models: theta = atan2(sqrt(X^2+Y^2), Z), phi = atan2(Y, X), u = u0 + r cos(phi),
// v = v0 + beta r sin(phi), with the radius r(theta) of
//  - Pajdla-Bakstein: r = a tan(theta / b) + c sin(theta / d);
//  - Kannala-Brandt: r = fx theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
//    (OpenCV's cv::fisheye, ROS's equidistant, Kalibr's pinhole-equi; beta = fy / fx).
// The field of view ends at fov_deg / 2 off the axis, or sooner where r(theta) stops growing.
class FisheyeCamera {
 public:
  explicit FisheyeCamera(const CameraDescription& description);

  int width() const { return width_; }
  int height() const { return height_; }
  const FisheyeParameters& parameters() const { return p_; }
  double max_theta() const { return max_theta_; }  // rad, half the field of view

  // Radius (px) at an off-axis angle theta (rad), its derivative, and its inverse on
  // [0, max_theta].
  double radius(double theta) const;
  double radius_derivative(double theta) const;
  std::optional<double> theta_of_radius(double r) const;

  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point) const;
  // d pixel / d (X, Y, Z) of a camera-frame point off the optical axis (analytic).
  Eigen::Matrix<double, 2, 3> project_jacobian(const Eigen::Vector3d& point) const;
  // Unit ray through a pixel; nullopt outside the field of view.
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const;
  bool in_image(const Eigen::Vector2d& pixel) const {
    return vision::in_image(pixel, width_, height_);
  }

 private:
  FisheyeParameters p_;
  int width_, height_;
  double max_theta_;
  bool kb_ = false;  // Kannala-Brandt, else Pajdla-Bakstein
};

// How long a stretch of ceiling the camera sees along the robot's forward axis (base x), on the
// line through the camera, for a ceiling `height` (m above the floor). 0 when it sees none.
double ceiling_view_length(const CameraDescription& camera, double height);

// How far apart (px) two descriptions of one camera put the same rays: the largest distance
// between `a`'s pixels on a 17 x 17 grid over its image (those whose ray it knows) and where `b`
// projects those rays. Infinity when the image sizes differ or `b` cannot see one of the rays.
// Tells a robot.json from the calibration a camera driver publishes (its CameraInfo), whatever
// the models' parameters.
double projection_difference_px(const CameraDescription& a, const CameraDescription& b);

}  // namespace lampnav::vision
