#include "lampnav/vision/lamp_tracker.hpp"

#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpImage.h>

#include <algorithm>
#include <memory>
#include <string>

namespace lampnav::vision {

void LampTrackerOptions::validate() const {
  if (max_tracks < 1 || max_tracks > 1000)
    throw InputError({"", "lamp tracker options", "max_tracks"}, "must be 1 to 1000");
  if (!(max_step_px > 0 && max_step_px < 10000))
    throw InputError({"", "lamp tracker options", "max_step_px"},
                     "must be a positive number of px");
}

namespace {

struct Track {
  int id = 0;
  int age = 0;
  vpDot2 dot;
};

bool contains(const std::array<int, 4>& box, double u, double v) {
  return u >= box[0] - 1 && u <= box[2] + 1 && v >= box[1] - 1 && v <= box[3] + 1;
}

}  // namespace

struct LampTracker::Impl {
  LampDetector detector;
  LampTrackerOptions o;
  unsigned threshold;
  // vpDot2 has no move: it would copy its outline (lists of edge points) whenever a track moved
  // in the vector, hundreds of allocations a frame. The tracks stay where they were made.
  std::vector<std::unique_ptr<Track>> tracks;
  std::vector<int> pending_ended;  // from reset()
  int next_id = 1;
  std::vector<std::uint8_t> grey, half;

  Impl(const CameraDescription& camera, const LampShapePrior& prior,
       const LampDetectorOptions& detector_options, const LampTrackerOptions& options)
      : detector(camera, prior, detector_options),
        o(options),
        threshold(static_cast<unsigned>(detector_options.threshold)) {
    o.validate();
  }

  void configure(vpDot2& dot) const {
    dot.setGraphics(false);
    dot.setComputeMoments(false);       // the detector measures; vpDot2 only follows the blob
    dot.setEllipsoidShapePrecision(0);  // lamps are rectangles, not ellipses
    dot.setSizePrecision(0);            // a lamp entering the view grows frame after frame
    dot.setGrayLevelMin(threshold);
    dot.setGrayLevelMax(255);
  }

  TrackedFrame process(const ImageView& image);
};

TrackedFrame LampTracker::Impl::process(const ImageView& image) {
  check_image(image, detector.width(), detector.height(), {"", "image", ""});
  const ImageView g = grey_view(image, grey);
  TrackedFrame out;
  out.ended = std::move(pending_ended);
  pending_ended.clear();
  LampDetections found = detector.detect(g);
  out.stats = found.stats;
  // vpDot2 follows each blob's outline; at half resolution the outline, and vpDot2's per-frame
  // copy of it, is half as long. Identity needs no more: the detector measures at full resolution.
  const int hw = g.width / 2, hh = g.height / 2;
  half.resize(static_cast<std::size_t>(hw) * hh);
  for (int v = 0; v < hh; ++v) {
    const std::uint8_t* __restrict a = g.data + static_cast<std::size_t>(2 * v) * g.row_stride();
    const std::uint8_t* __restrict b = a + g.row_stride();
    std::uint8_t* __restrict dst = half.data() + static_cast<std::size_t>(v) * hw;
    for (int u = 0; u < hw; ++u) {
      dst[u] =
          static_cast<std::uint8_t>((a[2 * u] + a[2 * u + 1] + b[2 * u] + b[2 * u + 1] + 2) >> 2);
    }
  }
  const vpImage<unsigned char> I(half.data(), static_cast<unsigned>(hh), static_cast<unsigned>(hw),
                                 false);
  // Half-resolution pixel centre (i, j) covers full-resolution pixels 2i, 2i + 1.
  auto to_full = [](const vpImagePoint& p) {
    return Eigen::Vector2d(2 * p.get_u() + 0.5, 2 * p.get_v() + 0.5);
  };
  std::vector<int> owner(found.lamps.size(), -1);  // detection -> track index
  std::vector<std::unique_ptr<Track>> kept;
  kept.reserve(tracks.size());
  for (auto& tp : tracks) {
    Track& t = *tp;
    const vpImagePoint before = t.dot.getCog();
    bool alive = true;
    try {
      // track() narrows the grey-level band around the blob's mean; a lamp is any pixel above
      // the detector's threshold, frame after frame.
      t.dot.setGrayLevelMin(threshold);
      t.dot.setGrayLevelMax(255);
      t.dot.track(I);
    } catch (const vpException&) {
      alive = false;
    }
    int match = -1;
    if (alive) {
      const Eigen::Vector2d cog = to_full(t.dot.getCog());
      if ((cog - to_full(before)).norm() > o.max_step_px) {
        alive = false;
      } else {
        double best = 1e18;
        for (std::size_t k = 0; k < found.lamps.size(); ++k) {
          const auto& d = found.lamps[k];
          if (!contains(d.bbox, cog.x(), cog.y())) continue;
          const double dist = (d.centre_px - cog).norm();
          if (dist < best) {
            best = dist;
            match = static_cast<int>(k);
          }
        }
        // No lamp-like blob where the track went (it left the view, or shrank below the area
        // filter), or an older track already holds that blob (two blobs merged): the track ends.
        if (match < 0 || owner[match] >= 0) alive = false;
      }
    }
    if (!alive) {
      out.ended.push_back(t.id);
      continue;
    }
    owner[match] = static_cast<int>(kept.size());
    ++t.age;
    kept.push_back(std::move(tp));
  }
  tracks = std::move(kept);
  // Lamps no track claimed start new tracks, seeded on a pixel of their blob.
  for (std::size_t k = 0; k < found.lamps.size(); ++k) {
    if (owner[k] >= 0 || static_cast<int>(tracks.size()) >= o.max_tracks) continue;
    auto t = std::make_unique<Track>();
    t->id = next_id++;
    t->age = 1;
    configure(t->dot);
    const auto& seed = found.lamps[k].seed;
    try {
      t->dot.initTracking(I, vpImagePoint(seed[1] / 2, seed[0] / 2), threshold, 255);
    } catch (const vpException&) {
      continue;  // the blob is not trackable (vpDot2 refused it); it is detected again next frame
    }
    owner[k] = static_cast<int>(tracks.size());
    tracks.push_back(std::move(t));
  }
  for (std::size_t k = 0; k < found.lamps.size(); ++k) {
    if (owner[k] < 0) continue;
    const Track& t = *tracks[owner[k]];
    out.lamps.push_back({t.id, t.age, t.age == 1, found.lamps[k]});
  }
  std::sort(out.lamps.begin(), out.lamps.end(),
            [](const TrackedLamp& a, const TrackedLamp& b) { return a.track_id < b.track_id; });
  return out;
}

LampTracker::LampTracker(const CameraDescription& camera, const LampShapePrior& prior,
                         const LampDetectorOptions& detector, const LampTrackerOptions& options)
    : impl_(std::make_unique<Impl>(camera, prior, detector, options)) {}
LampTracker::~LampTracker() = default;
LampTracker::LampTracker(LampTracker&&) noexcept = default;
LampTracker& LampTracker::operator=(LampTracker&&) noexcept = default;

TrackedFrame LampTracker::process(const ImageView& image) { return impl_->process(image); }

void LampTracker::reset() {
  for (const auto& t : impl_->tracks) impl_->pending_ended.push_back(t->id);
  impl_->tracks.clear();
}

int LampTracker::live_tracks() const { return static_cast<int>(impl_->tracks.size()); }

}  // namespace lampnav::vision
