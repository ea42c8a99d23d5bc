#include "lampnav/vision/omni_detector.hpp"

#include <algorithm>
#include <cmath>

#include "blobs.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::vision {

void OmniDetectorOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "omni detector options", field}, msg);
  };
  if (threshold < 1 || threshold > 255) fail("threshold", "must be 1 to 255");
  if (bloom_threshold <= threshold || bloom_threshold > 255)
    fail("bloom_threshold", "must be above threshold and at most 255");
  if (min_pixels < 1) fail("min_pixels", "must be at least 1");
  if (big_blob_pixels <= min_pixels) fail("big_blob_pixels", "must be above min_pixels");
  if (max_blobs < 1) fail("max_blobs", "must be at least 1");
  if (!(max_theta_deg > 0 && max_theta_deg <= 180)) fail("max_theta_deg", "must be 0 to 180");
}

struct OmniLampDetector::Impl {
  FisheyeCamera model;
  OmniDetectorOptions o;
  std::vector<std::uint8_t> grey, crop;
  detail::BlobLabeller first, second;

  Impl(const CameraDescription& c, const OmniDetectorOptions& opt) : model(c), o(opt) {
    o.validate();
  }

  // Fills `out` from blob b of `lab`, whose pixel (0, 0) is image pixel (du, dv). False when the
  // blob is outside the usable view.
  bool describe(const detail::BlobLabeller& lab, const detail::Blob& b, int du, int dv,
                OmniBlob* out) const {
    // First and second moments of the pixels, about the first run's start (for precision).
    const detail::Run& origin = lab.run(b.first_run);
    double su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
    // 1^2 + ... + m^2; as a polynomial S(m) - S(m - 1) = m^2 for every integer m, so the sum of
    // u^2 over u0..u1 is S(u1) - S(u0 - 1) whatever their signs.
    const auto sum_squares = [](double m) { return m * (m + 1) * (2 * m + 1) / 6; };
    for (int k = 0; k < b.run_count; ++k) {
      const detail::Run& r = lab.run(b.first_run + k);
      const double n = r.u1 - r.u0 + 1;
      const double u0 = r.u0 - origin.u0, u1 = r.u1 - origin.u0, v = r.row - origin.row;
      const double run_u = n * (u0 + u1) / 2.0;
      su += run_u;
      sv += n * v;
      suu += sum_squares(u1) - sum_squares(u0 - 1);
      svv += n * v * v;
      suv += v * run_u;
    }
    const double N = b.pixels;
    const double mu = su / N, mv = sv / N;
    out->pixels = b.pixels;
    out->perimeter = lab.perimeter(b);
    out->centroid_px = Eigen::Vector2d(mu + origin.u0 + du, mv + origin.row + dv);
    const auto& p = model.parameters();
    const Eigen::Vector2d d(out->centroid_px.x() - p.u0, (out->centroid_px.y() - p.v0) / p.beta);
    out->radius_px = d.norm();
    out->azimuth = std::atan2(d.y(), d.x());
    const auto ray = model.unproject(out->centroid_px);
    if (!ray) return false;
    out->ray = ray->normalized();
    out->theta = std::atan2(out->ray.head<2>().norm(), out->ray.z());
    // px a radian at the blob: the lens model's own derivative of its radius.
    const double scale = std::max(1.0, model.radius_derivative(out->theta));
    out->angular_radius = std::sqrt(b.pixels / M_PI) / scale;
    // The pixels' covariance, its axes: a streak when the long one is twice the short one.
    const double cuu = suu / N - mu * mu, cvv = svv / N - mv * mv, cuv = suv / N - mu * mv;
    const double mean = (cuu + cvv) / 2, diff = std::hypot((cuu - cvv) / 2, cuv);
    const double long_var = mean + diff, short_var = std::max(0.0, mean - diff);
    if (long_var >= 4 * short_var && long_var > 0) {
      const double angle = 0.5 * std::atan2(2 * cuv, cuu - cvv);
      const Eigen::Vector2d along =
          std::sqrt(3 * long_var) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      const auto end0 = model.unproject(out->centroid_px + along);
      const auto end1 = model.unproject(out->centroid_px - along);
      if (end0 && end1) {
        out->streak = true;
        out->streak_ends[0] = end0->normalized();
        out->streak_ends[1] = end1->normalized();
        out->streak_half_width = std::sqrt(3 * short_var) / scale;
      }
    }
    return out->theta <= o.max_theta_deg * M_PI / 180;
  }

  void add(const detail::BlobLabeller& lab, const detail::Blob& b, int du, int dv, bool bloom,
           OmniDetection* out) const {
    if (b.pixels < o.min_pixels) {
      ++out->too_small;
      return;
    }
    OmniBlob blob;
    blob.from_bloom = bloom;
    if (!describe(lab, b, du, dv, &blob)) {
      ++out->outside_view;
      return;
    }
    out->blobs.push_back(blob);
  }

  OmniDetection detect(const ImageView& image) {
    check_image(image, model.width(), model.height(), {"", "image", ""});
    const ImageView g = grey_view(image, grey);
    first.label(g, static_cast<std::uint8_t>(o.threshold));
    OmniDetection out;
    out.raw_blobs = static_cast<int>(first.blobs().size());
    if (out.raw_blobs > o.max_blobs) {
      out.flooded = true;
      return out;
    }
    for (const detail::Blob& b : first.blobs()) {
      if (b.pixels <= o.big_blob_pixels) {
        add(first, b, 0, 0, false, &out);
        continue;
      }
      // A bloom: label its pixels again at the higher threshold (paper 1, Fig. 9). They are copied
      // run by run into its bounding box, dark elsewhere: the box of a bloom near the horizon can
      // be half the image, and it may hold other blobs, which are not this bloom's to split.
      const int w = b.u1 - b.u0 + 1, h = b.v1 - b.v0 + 1;
      crop.assign(static_cast<std::size_t>(w) * h, 0);
      for (int k = 0; k < b.run_count; ++k) {
        const detail::Run& r = first.run(b.first_run + k);
        std::copy_n(g.data + static_cast<std::size_t>(r.row) * g.row_stride() + r.u0,
                    r.u1 - r.u0 + 1,
                    crop.data() + static_cast<std::size_t>(r.row - b.v0) * w + (r.u0 - b.u0));
      }
      second.label(ImageView{crop.data(), w, h, 1, 1, static_cast<std::size_t>(w)},
                   static_cast<std::uint8_t>(o.bloom_threshold));
      if (second.blobs().empty()) {  // no saturated core: keep the blob as it was
        add(first, b, 0, 0, false, &out);
        continue;
      }
      ++out.split_blooms;
      for (const detail::Blob& c : second.blobs()) add(second, c, b.u0, b.v0, true, &out);
    }
    return out;
  }
};

OmniLampDetector::OmniLampDetector(const CameraDescription& camera,
                                   const OmniDetectorOptions& options)
    : impl_(std::make_unique<Impl>(camera, options)) {}
OmniLampDetector::~OmniLampDetector() = default;
OmniLampDetector::OmniLampDetector(OmniLampDetector&&) noexcept = default;
OmniLampDetector& OmniLampDetector::operator=(OmniLampDetector&&) noexcept = default;
OmniDetection OmniLampDetector::detect(const ImageView& image) { return impl_->detect(image); }
const OmniDetectorOptions& OmniLampDetector::options() const { return impl_->o; }

}  // namespace lampnav::vision
