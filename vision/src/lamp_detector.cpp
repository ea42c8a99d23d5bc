#include "lampnav/vision/lamp_detector.hpp"

#include <Eigen/LU>  // determinant
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include "blobs.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "run_mask.hpp"
#include "shape_fit.hpp"

namespace lampnav::vision {

using Eigen::Vector2d;

namespace {

void require(bool ok, const char* what, const char* field, const std::string& message) {
  if (!ok) throw InputError({"", what, field}, message);
}

// A blob's weighted area, centroid and central second moments (each pixel a small square).
struct Moments {
  double m0 = 0, cx = 0, cy = 0, mu20 = 0, mu02 = 0, mu11 = 0;
  int pixels = 0;
};

}  // namespace

const char* to_string(LampView view) {
  switch (view) {
    case LampView::full:
      return "full";
    case LampView::completed:
      return "completed";
    case LampView::partial:
      return "partial";
  }
  return "?";
}

void LampShapePrior::validate() const {
  const char* what = "lamp shape";
  require(length > 0 && std::isfinite(length), what, "length", "must be a positive length in m");
  require(width > 0 && width <= length, what, "width", "must be positive and at most the length");
  require(min_distance > 0 && std::isfinite(min_distance), what, "min_distance",
          "must be positive (the lamps must be above the camera)");
  require(max_distance >= min_distance && std::isfinite(max_distance), what, "max_distance",
          "must be at least min_distance");
  require(nominal_distance >= min_distance && nominal_distance <= max_distance, what,
          "nominal_distance", "must lie between min_distance and max_distance");
}

void LampDetectorOptions::validate() const {
  const char* what = "lamp detector options";
  require(threshold >= 1 && threshold <= 255, what, "threshold", "must be 1 to 255");
  require(min_area_fraction > 0 && min_area_fraction < 1, what, "min_area_fraction",
          "must be between 0 and 1");
  require(max_area_fraction > 1 && max_area_fraction < 10, what, "max_area_fraction",
          "must be between 1 and 10");
  require(complete_min_fraction >= min_area_fraction && complete_min_fraction <= 1, what,
          "complete_min_fraction", "must be between min_area_fraction and 1");
  require(opening_radius >= 0 && opening_radius <= 5, what, "opening_radius", "must be 0 to 5 px");
  require(max_shape_error > 0 && max_shape_error < 1, what, "max_shape_error",
          "must be between 0 and 1");
  require(max_fit_rms_px > 0 && max_fit_rms_px <= 10, what, "max_fit_rms_px",
          "must be between 0 and 10 px");
}

struct LampDetector::Impl {
  PinholeCamera model;
  LampShapePrior prior;
  LampDetectorOptions o;
  int w, h;
  // Per pixel: undistorted normalized coordinates of its centre and the normalized area it covers.
  // Kept together, so that a pixel's three are one read from memory (the tables are larger than
  // the caches: 1.6 MB at 352x288).
  struct PixelLut {
    float x, y, w;
  };
  std::vector<PixelLut> lut;
  // Per row, running sums of the moments' terms over its first 4k pixels (k = 0..w/4), so that
  // a run of pixels costs two lookups and at most four pixels' terms (the nearer entry, before or
  // after the run's end), not one term per pixel. One cache line an entry: 1.6 MB at 352x288,
  // 4.9 MB at 640x480.
  static constexpr int kSumStride = 4;
  struct alignas(64) RowSums {
    double w = 0, wx = 0, wy = 0, wxx = 0, wxy = 0, wyy = 0, ww = 0;
    void add(double wt, double x, double y) {
      w += wt, wx += wt * x, wy += wt * y;
      wxx += wt * x * x, wxy += wt * x * y, wyy += wt * y * y, ww += wt * wt;
    }
    void remove(double wt, double x, double y) {
      w -= wt, wx -= wt * x, wy -= wt * y;
      wxx -= wt * x * x, wxy -= wt * x * y, wyy -= wt * y * y, ww -= wt * wt;
    }
  };
  int sums_per_row = 0;
  std::vector<RowSums> row_sums;
  // The sums over pixels [0, u) of row v, 0 <= u <= w.
  RowSums sums_before(int u, int v) const {
    const RowSums* row = row_sums.data() + static_cast<std::size_t>(v) * sums_per_row;
    const int k = u / kSumStride, past = u % kSumStride;
    if (past <= kSumStride / 2 || k + 1 >= sums_per_row) {
      RowSums s = row[k];
      for (int j = u - past; j < u; ++j) {
        const std::size_t i = index(j, v);
        s.add(lut[i].w, lut[i].x, lut[i].y);
      }
      return s;
    }
    RowSums s = row[k + 1];
    for (int j = u; j < (k + 1) * kSumStride; ++j) {
      const std::size_t i = index(j, v);
      s.remove(lut[i].w, lut[i].x, lut[i].y);
    }
    return s;
  }
  double area_nominal, area_min, area_max;  // of a whole lamp, normalized units^2
  double min_pixels, max_pixels;            // pixel-count bounds that cannot drop a lamp
  // Scratch, reused frame to frame.
  std::vector<std::uint8_t> grey;
  detail::BlobLabeller blobs;
  detail::RunMask mask_runs, opened_runs;
  detail::RunOpening opening;
  detail::EdgePoints edges;
  detail::FitScratch fit_scratch;  // fit_shape's

  Impl(const CameraDescription& camera, const LampShapePrior& p, const LampDetectorOptions& opt)
      : model(camera), prior(p), o(opt), w(camera.width), h(camera.height) {
    prior.validate();
    o.validate();
    const std::size_t n = static_cast<std::size_t>(w) * h;
    lut.resize(n);
    const auto& k = model.parameters();
    double w_min = 1e9, w_max = 0;
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const Vector2d xy = model.normalized_of_pixel(Vector2d(u, v));
        const double det = std::fabs(model.distort_jacobian(xy).determinant()) * k.fx * k.fy;
        lut[i] = {static_cast<float>(xy.x()), static_cast<float>(xy.y()),
                  static_cast<float>(1.0 / det)};
        w_min = std::min(w_min, 1.0 / det);
        w_max = std::max(w_max, 1.0 / det);
      }
    }
    sums_per_row = w / kSumStride + 1;
    row_sums.resize(static_cast<std::size_t>(sums_per_row) * h);
    for (int v = 0; v < h; ++v) {
      RowSums* r = row_sums.data() + static_cast<std::size_t>(sums_per_row) * v;
      RowSums running;
      for (int u = 0; u < w; ++u) {
        if (u % kSumStride == 0) r[u / kSumStride] = running;
        const std::size_t i = index(u, v);
        running.add(lut[i].w, lut[i].x, lut[i].y);
      }
      if (w % kSumStride == 0) r[w / kSumStride] = running;
    }
    const double face =
        prior.rectangle ? prior.length * prior.width : M_PI / 4 * prior.length * prior.length;
    area_nominal = face / (prior.nominal_distance * prior.nominal_distance);
    area_min = face / (prior.max_distance * prior.max_distance);
    area_max = face / (prior.min_distance * prior.min_distance);
    min_pixels = o.min_area_fraction * area_min / w_max * 0.8;
    max_pixels = o.max_area_fraction * area_max / w_min * 1.25 + 64;
    border_chord = shortest_border_chord();
  }

  // The fewest pixels of the left or right image column that a blob measured as a lamp can cover
  // there (see LampDetector::border_chord_px). A straight image side cuts a lamp in one of three
  // ways. Across two opposite sides of a rectangle: the chord is at least its short side. Across
  // a corner only (one corner in view): the visible part is a right triangle on the chord, of
  // area at most chord^2 / 4, and it holds at least min_pixels. Leaving one corner out (three in
  // view): the chord can be short, but the lamp was cut across two sides on its way in, unless it
  // moved by its own width in one frame. A disc: the visible segment holds min_pixels.
  double shortest_border_chord() const {
    // The most and the least a step of one pixel down a side column moves in the normalized
    // plane: the fewest and the most pixels a length there spans.
    double most = 0, least = 1e9;
    for (int u : {0, w - 1}) {
      for (int v = 0; v + 1 < h; ++v) {
        const PixelLut &p = lut[index(u, v)], &q = lut[index(u, v + 1)];
        const double d = std::hypot(q.x - p.x, q.y - p.y);
        most = std::max(most, d);
        least = std::min(least, d);
      }
    }
    if (!(most > 0 && least > 0)) return 1;  // a degenerate lens: read every pixel
    if (prior.rectangle) {
      const double across = prior.width / prior.max_distance / most;
      return std::min(across, 2 * std::sqrt(min_pixels));
    }
    // A segment of a disc of radius r (px, the largest image: the flattest segment of a given
    // area) cut at half-angle a has area r^2 (a - sin a cos a) and chord 2 r sin a.
    const double r = 0.5 * prior.length / prior.min_distance / least;
    double lo = 0, hi = M_PI / 2;
    for (int i = 0; i < 60; ++i) {
      const double a = 0.5 * (lo + hi);
      (r * r * (a - std::sin(a) * std::cos(a)) < min_pixels ? lo : hi) = a;
    }
    return std::min(2 * r * std::sin(lo), prior.length / prior.max_distance / most);
  }
  double border_chord = 1;

  std::size_t index(int u, int v) const { return static_cast<std::size_t>(v) * w + u; }

  LampDetections detect(const ImageView& image);
  LampDetections detect_in(const ImageView& image, std::vector<PixelBox> windows);
  // Measures the blobs of the last labelling into `out`; false when one spills out of `box`.
  bool measure_blobs(const ImageView& g, const PixelBox& box, LampDetections& out);
  bool measure(const detail::Blob& c, const ImageView& g, LampDetection& out, DetectionStats& st);
  bool complete(const detail::Blob& c, const ImageView& g, int pad, const detail::RunMask& open,
                LampDetection& out);
  // Of the opened mask of blob `c` (padded by `pad`): its moments, the pixel nearest the middle
  // of its box, and whether it reaches the image's border.
  Moments moments(const detail::Blob& c, int pad, const detail::RunMask& open) const;
  std::array<int, 2> seed_near_middle(const detail::Blob& c, int pad,
                                      const detail::RunMask& open) const;
  bool touches_image_border(const detail::Blob& c, int pad, const detail::RunMask& open) const;
};

LampDetections LampDetector::Impl::detect(const ImageView& image) {
  check_image(image, w, h, {"", "image", ""});
  const ImageView g = grey_view(image, grey);
  blobs.label(g, static_cast<std::uint8_t>(o.threshold));
  LampDetections out;
  out.pixels_read = static_cast<long>(w) * h;
  measure_blobs(g, PixelBox{0, 0, w - 1, h - 1}, out);
  return out;
}

LampDetections LampDetector::Impl::detect_in(const ImageView& image,
                                             std::vector<PixelBox> windows) {
  check_image(image, w, h, {"", "image", ""});
  const ImageView g = grey_view(image, grey);
  for (auto& b : windows)
    b = {std::max(b.u0, 0), std::max(b.v0, 0), std::min(b.u1, w - 1), std::min(b.v1, h - 1)};
  windows.erase(
      std::remove_if(windows.begin(), windows.end(), [](const PixelBox& b) { return b.empty(); }),
      windows.end());
  // Overlapping windows become their bounding box, until none overlap: a blob is then read once.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < windows.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < windows.size(); ++j) {
        if (!windows[i].overlaps(windows[j])) continue;
        PixelBox& a = windows[i];
        const PixelBox& b = windows[j];
        a = {std::min(a.u0, b.u0), std::min(a.v0, b.v0), std::max(a.u1, b.u1),
             std::max(a.v1, b.v1)};
        windows.erase(windows.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
        break;
      }
    }
  }
  LampDetections out;
  for (const PixelBox& box : windows) {
    out.pixels_read += box.area();
    blobs.label(g, static_cast<std::uint8_t>(o.threshold), box);
    if (!measure_blobs(g, box, out)) {
      out.spilled = true;
      return out;
    }
  }
  return out;
}

bool LampDetector::Impl::measure_blobs(const ImageView& g, const PixelBox& box,
                                       LampDetections& out) {
  // A blob on an edge of the box that is not the image's own edge may go on outside the box.
  for (const detail::Blob& c : blobs.blobs()) {
    if ((c.u0 == box.u0 && box.u0 > 0) || (c.v0 == box.v0 && box.v0 > 0) ||
        (c.u1 == box.u1 && box.u1 < w - 1) || (c.v1 == box.v1 && box.v1 < h - 1))
      return false;
  }
  out.stats.blobs += static_cast<int>(blobs.blobs().size());
  for (const detail::Blob& c : blobs.blobs()) {
    const std::size_t before = out.lamps.size();
    if (c.pixels < min_pixels) {
      ++out.stats.too_small;
    } else if (c.pixels > max_pixels) {
      ++out.stats.too_large;
    } else {
      LampDetection d;
      if (measure(c, g, d, out.stats)) out.lamps.push_back(d);
    }
    const bool at_border = c.u0 == 0 || c.v0 == 0 || c.u1 == w - 1 || c.v1 == h - 1;
    if (at_border && out.lamps.size() == before)
      out.border_blobs.push_back({c.u0, c.v0, c.u1, c.v1});
  }
  return true;
}

bool LampDetector::Impl::measure(const detail::Blob& c, const ImageView& g, LampDetection& out,
                                 DetectionStats& st) {
  // The component's mask with a margin, as runs; on sides where the lamp leaves the image the
  // mask is continued outwards so that the opening does not eat the cut edge.
  const int r = o.opening_radius, pad = 2 * r + 1;
  const int mw = c.u1 - c.u0 + 1 + 2 * pad, mh = c.v1 - c.v0 + 1 + 2 * pad;
  const bool extend = r > 0;
  const bool cut_left = extend && c.u0 == 0, cut_right = extend && c.u1 == w - 1;
  const bool cut_top = extend && c.v0 == 0, cut_bottom = extend && c.v1 == h - 1;
  // Row y of the padded mask: the blob's runs of its row, or a copy of the first or last.
  int next_run = 0;
  auto add_blob_row = [&](int y) {
    const int v = y - pad + c.v0;
    while (next_run < c.run_count && blobs.run(c.first_run + next_run).row < v) ++next_run;
    for (int j = next_run; j < c.run_count && blobs.run(c.first_run + j).row == v; ++j) {
      const detail::Run& run = blobs.run(c.first_run + j);
      int a = run.u0 - c.u0 + pad, b = run.u1 - c.u0 + pad;
      if (cut_left && a == pad) a = 0;
      if (cut_right && b == mw - pad - 1) b = mw - 1;
      mask_runs.add(a, b);
    }
  };
  mask_runs.reset(mw, mh);
  for (int y = 0; y < mh; ++y) {
    mask_runs.begin_row();
    if (y < pad) {
      if (cut_top) add_blob_row(pad);
    } else if (y >= mh - pad) {
      if (cut_bottom) add_blob_row(mh - pad - 1);
    } else {
      add_blob_row(y);
    }
  }
  mask_runs.end_rows();
  if (r > 0) opening.open(mask_runs, r, opened_runs);
  const detail::RunMask& open_runs = r > 0 ? opened_runs : mask_runs;
  // Moments in undistorted normalized coordinates, each pixel weighted by the area it covers.
  const Moments m = moments(c, pad, open_runs);
  if (m.pixels == 0 || m.m0 <= 0) {
    ++st.too_small;
    return false;
  }
  const double cx = m.cx, cy = m.cy, mu20 = m.mu20, mu02 = m.mu02, mu11 = m.mu11;
  const double half_sum = 0.5 * (mu20 + mu02);
  const double root = std::sqrt(0.25 * (mu20 - mu02) * (mu20 - mu02) + mu11 * mu11);
  const double l1 = half_sum + root, l2 = std::max(0.0, half_sum - root);
  out.seed = seed_near_middle(c, pad, open_runs);
  // After the opening: a fringe pixel at the border is no cut.
  const bool touches_border = touches_image_border(c, pad, open_runs);
  out.centre = Vector2d(cx, cy);
  out.orientation = wrap_axis_angle(0.5 * std::atan2(2 * mu11, mu20 - mu02));
  // Uniform rectangle: variance L^2 / 12 along a side; uniform disc: D^2 / 16 on any axis.
  const double k = prior.rectangle ? 12.0 : 16.0;
  out.length = std::sqrt(k * l1);
  out.width = std::sqrt(k * l2);
  out.area = m.m0;
  out.pixels = m.pixels;
  out.bbox = {c.u0, c.v0, c.u1, c.v1};
  out.visible_fraction = m.m0 / area_nominal;
  if (m.m0 < o.min_area_fraction * area_min) {
    ++st.too_small;
    return false;
  }
  if (m.m0 > o.max_area_fraction * area_max) {
    ++st.too_large;
    return false;
  }
  if (!touches_border) {
    // The axes of a whole lamp must match the prior at some distance in the range.
    const double e = o.max_shape_error;
    const double len_lo = prior.length / prior.max_distance * (1 - e);
    const double len_hi = prior.length / prior.min_distance * (1 + e);
    const double wid_lo = prior.width / prior.max_distance * (1 - e);
    const double wid_hi = prior.width / prior.min_distance * (1 + e);
    if (out.length < len_lo || out.length > len_hi || out.width < wid_lo || out.width > wid_hi) {
      ++st.wrong_shape;
      return false;
    }
    out.view = LampView::full;
    out.visible_fraction = std::min(out.visible_fraction, 1.0);
  } else {
    out.view = LampView::partial;
    if (out.visible_fraction >= o.complete_min_fraction) {
      if (complete(c, g, pad, open_runs, out)) {
        out.view = LampView::completed;
      } else {
        ++st.completion_failed;
      }
    }
  }
  out.centre_px = model.pixel_of_normalized(out.centre);
  return true;
}

Moments LampDetector::Impl::moments(const detail::Blob& c, int pad,
                                    const detail::RunMask& open) const {
  // Each run of the opened mask inside the blob's box adds the difference of its row's running
  // sums at its ends. A pixel is a small square, not a point: its own spread adds wt^2 / 12 to
  // each axis.
  RowSums s;
  long pixels = 0;
  const int n = c.u1 - c.u0 + 1;
  for (int v = c.v0; v <= c.v1; ++v) {
    const int y = v - c.v0 + pad;
    for (const detail::Span* sp = open.row_begin(y); sp != open.row_end(y); ++sp) {
      const int a = std::max(sp->a - pad, 0), end = std::min(sp->b - pad + 1, n);
      if (a >= end) continue;
      const RowSums lo = sums_before(c.u0 + a, v), hi = sums_before(c.u0 + end, v);
      s.w += hi.w - lo.w, s.wx += hi.wx - lo.wx, s.wy += hi.wy - lo.wy;
      s.wxx += hi.wxx - lo.wxx, s.wxy += hi.wxy - lo.wxy, s.wyy += hi.wyy - lo.wyy;
      s.ww += hi.ww - lo.ww;
      pixels += end - a;
    }
  }
  Moments m;
  m.pixels = static_cast<int>(pixels);
  m.m0 = s.w;
  if (m.pixels == 0 || s.w <= 0) return m;
  m.cx = s.wx / s.w;
  m.cy = s.wy / s.w;
  m.mu20 = (s.wxx + s.ww / 12) / s.w - m.cx * m.cx;
  m.mu02 = (s.wyy + s.ww / 12) / s.w - m.cy * m.cy;
  m.mu11 = s.wxy / s.w - m.cx * m.cy;
  return m;
}

std::array<int, 2> LampDetector::Impl::seed_near_middle(const detail::Blob& c, int pad,
                                                        const detail::RunMask& open) const {
  // The set pixel with the least |u - mid_u| + |v - mid_v|, the first in row order on ties, and
  // left of mid_u before right of it in a row.
  const int mid_u = (c.u0 + c.u1) / 2, mid_v = (c.v0 + c.v1) / 2;
  int best = 1 << 30;
  std::array<int, 2> seed{mid_u, mid_v};
  for (int v = c.v0; v <= c.v1; ++v) {
    const int dv = std::abs(v - mid_v);
    if (dv >= best) continue;
    const int y = v - c.v0 + pad;
    int t_row = 1 << 30, u_row = mid_u;
    for (const detail::Span* sp = open.row_begin(y); sp != open.row_end(y); ++sp) {
      // The span in image columns, within the blob's box.
      const int a = std::max(sp->a - pad + c.u0, c.u0), b = std::min(sp->b - pad + c.u0, c.u1);
      if (a > b) continue;
      const int u = b < mid_u ? b : a > mid_u ? a : mid_u;
      const int t = std::abs(u - mid_u);
      if (t < t_row || (t == t_row && u < mid_u)) t_row = t, u_row = u;
    }
    if (dv + t_row < best) {
      best = dv + t_row;
      seed = {u_row, v};
    }
  }
  return seed;
}

bool LampDetector::Impl::touches_image_border(const detail::Blob& c, int pad,
                                              const detail::RunMask& open) const {
  // A set pixel of the blob's box on the image's first or last row or column.
  auto row_has = [&](int v) {
    const int y = v - c.v0 + pad;
    for (const detail::Span* sp = open.row_begin(y); sp != open.row_end(y); ++sp)
      if (sp->b >= pad && sp->a <= pad + (c.u1 - c.u0)) return true;
    return false;
  };
  auto column_has = [&](int u) {
    const int x = pad + (u - c.u0);
    for (int v = c.v0; v <= c.v1; ++v) {
      const int y = v - c.v0 + pad;
      for (const detail::Span* sp = open.row_begin(y); sp != open.row_end(y); ++sp)
        if (sp->a <= x && x <= sp->b) return true;
    }
    return false;
  };
  return (c.v0 == 0 && row_has(0)) || (c.v1 == h - 1 && row_has(h - 1)) ||
         (c.u0 == 0 && column_has(0)) || (c.u1 == w - 1 && column_has(w - 1));
}

// Completion of a lamp cut by the image border (paper 2, Fig. 5): the visible edges, located to a
// fraction of a pixel where the grey level crosses the threshold, are fitted with the known shape.
bool LampDetector::Impl::complete(const detail::Blob& c, const ImageView& g, int pad,
                                  const detail::RunMask& open, LampDetection& out) {
  edges.clear();
  const double level = o.threshold - 0.5;
  auto edge = [&](int u, int v, int un, int vn, std::uint8_t gi, std::uint8_t go) {
    const double t = gi > go ? std::clamp((gi - level) / (gi - go), 0.0, 1.0) : 0.5;
    const std::size_t a = index(u, v), b = index(un, vn);
    edges.emplace_back(lut[a].x + t * (lut[b].x - lut[a].x), lut[a].y + t * (lut[b].y - lut[a].y));
  };
  // Border pixels of the cut tell on which side of the visible part the rest of the lamp lies.
  Vector2d border_sum = Vector2d::Zero();
  int border_n = 0;
  const std::size_t stride = g.row_stride();
  const int box_w = c.u1 - c.u0 + 1;
  // The opened mask of measure(), as runs, padded: a pixel's 4-neighbours are always in it.
  // Inside the image it is the visible lamp exactly (its extension past a cut lies outside the
  // image), and its runs neither overlap nor touch: a pixel has a dark left (right) neighbour
  // exactly when it starts (ends) a run, and a dark neighbour above (below) when no run of that
  // row covers it. Each run is walked in stretches over which that stays the same; the pixels
  // of a stretch with a dark neighbour above or below, on the image's top or bottom row, and
  // each run's ends are looked at, in column order, as the pixels of the row.
  for (int v = c.v0; v <= c.v1; ++v) {
    const int y = v - c.v0 + pad;
    const std::uint8_t* grey_row = g.data + static_cast<std::size_t>(v) * stride;
    const bool border_row = v == 0 || v == h - 1;
    // The runs of the rows above and below, passed over as the columns grow: whether one covers
    // column j, and the first column (up to b + 1) where that changes.
    struct Cover {
      const detail::Span *at, *end;
      bool set = false;
      int next = 0;
    };
    Cover up{open.row_begin(y - 1), open.row_end(y - 1)};
    Cover down{open.row_begin(y + 1), open.row_end(y + 1)};
    const auto advance = [pad](Cover& t, int j, int b) {
      while (t.at != t.end && t.at->b - pad < j) ++t.at;
      t.set = t.at != t.end && t.at->a - pad <= j;
      t.next = t.at == t.end ? b + 1 : t.set ? t.at->b - pad + 1 : t.at->a - pad;
    };
    for (const detail::Span* sp = open.row_begin(y); sp != open.row_end(y); ++sp) {
      // Columns j = u - c.u0, in the blob's box.
      const int a = std::max(sp->a - pad, 0), b = std::min(sp->b - pad, box_w - 1);
      if (a > b) continue;
      for (int j = a; j <= b;) {
        advance(up, j, b);
        advance(down, j, b);
        const int last = std::min({b, up.next - 1, down.next - 1});
        const bool above = v > 0 && !up.set, below = v < h - 1 && !down.set;
        const auto look = [&](int k) {
          const int u = c.u0 + k;
          const bool left = k == a && u > 0, right = k == b && u < w - 1;
          if (border_row || u == 0 || u == w - 1) {
            const std::size_t i = index(u, v);
            border_sum += Vector2d(lut[i].x, lut[i].y);
            ++border_n;
          }
          if (!(left || right || below || above)) return;
          const std::uint8_t gi = grey_row[u];
          // The neighbours in the order right, left, below, above.
          if (right) edge(u, v, u + 1, v, gi, grey_row[u + 1]);
          if (left) edge(u, v, u - 1, v, gi, grey_row[u - 1]);
          if (below) edge(u, v, u, v + 1, gi, (grey_row + stride)[u]);
          if (above) edge(u, v, u, v - 1, gi, (grey_row - stride)[u]);
        };
        if (above || below || border_row) {
          for (int k = j; k <= last; ++k) look(k);
        } else {
          // Nothing dark above or below: only the run's ends, where the stretch holds them.
          if (j == a) look(a);
          if (last == b && b != a) look(b);
        }
        j = last + 1;
      }
    }
  }
  if (edges.size() < 16 || border_n == 0) return false;
  const double half_a = prior.length / (2 * prior.nominal_distance);
  const double half_b =
      (prior.rectangle ? prior.width : prior.length) / (2 * prior.nominal_distance);
  const double px = 1.0 / model.parameters().fx;  // one pixel in normalized units (about)
  // Initial guesses: the visible centroid moved towards the cut, along and across the lamp, so
  // that the uncut end (or side) stays where it is seen.
  const Vector2d centroid = out.centre;
  const Vector2d to_cut = border_sum / border_n - centroid;
  const Vector2d e(std::cos(out.orientation), std::sin(out.orientation));
  const Vector2d n(-e.y(), e.x());
  double s_lo = 1e9, s_hi = -1e9, t_lo = 1e9, t_hi = -1e9;
  for (const auto& p : edges) {
    const Vector2d d = p - centroid;
    s_lo = std::min(s_lo, d.dot(e));
    s_hi = std::max(s_hi, d.dot(e));
    t_lo = std::min(t_lo, d.dot(n));
    t_hi = std::max(t_hi, d.dot(n));
  }
  const double along = to_cut.dot(e) >= 0 ? 1.0 : -1.0;
  const double across = to_cut.dot(n) >= 0 ? 1.0 : -1.0;
  const Vector2d from_end = centroid + e * ((along > 0 ? s_lo : s_hi) + along * half_a);
  const Vector2d from_side = centroid + n * ((across > 0 ? t_lo : t_hi) + across * half_b);
  const Vector2d from_both = from_end + n * ((across > 0 ? t_lo : t_hi) + across * half_b);
  detail::ShapeFit best;
  for (const Vector2d& start : {from_end, from_side, from_both, centroid}) {
    const detail::ShapeFit f = detail::fit_shape(edges, prior.rectangle, half_a, half_b, start,
                                                 out.orientation, 2 * px, fit_scratch);
    if (f.ok && (!best.ok || f.rms < best.rms)) best = f;
    if (best.ok && best.rms < 0.5 * px) break;  // edges fit to noise level: no other start needed
  }
  if (!best.ok || best.rms / px > o.max_fit_rms_px) return false;
  out.centre = best.centre;
  if (prior.rectangle) out.orientation = wrap_axis_angle(best.orientation);
  out.length = 2 * half_a;
  out.width = 2 * half_b;
  out.fit_points = best.points;
  out.fit_rms_px = best.rms / px;
  return true;
}

LampDetector::LampDetector(const CameraDescription& camera, const LampShapePrior& prior,
                           const LampDetectorOptions& options)
    : impl_(std::make_unique<Impl>(camera, prior, options)) {}
LampDetector::~LampDetector() = default;
LampDetector::LampDetector(LampDetector&&) noexcept = default;
LampDetector& LampDetector::operator=(LampDetector&&) noexcept = default;

LampDetections LampDetector::detect(const ImageView& image) { return impl_->detect(image); }
LampDetections LampDetector::detect_in(const ImageView& image, std::vector<PixelBox> windows) {
  return impl_->detect_in(image, std::move(windows));
}
double LampDetector::expected_area() const { return impl_->area_nominal; }
double LampDetector::border_chord_px() const { return impl_->border_chord; }
const LampShapePrior& LampDetector::prior() const { return impl_->prior; }
const LampDetectorOptions& LampDetector::options() const { return impl_->o; }
int LampDetector::width() const { return impl_->w; }
int LampDetector::height() const { return impl_->h; }

}  // namespace lampnav::vision
