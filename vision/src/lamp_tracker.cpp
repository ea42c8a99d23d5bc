#include "lampnav/vision/lamp_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lampnav::vision {

using Eigen::Vector2d;

void LampTrackerOptions::validate() const {
  const char* what = "lamp tracker options";
  if (max_tracks < 1 || max_tracks > 1000)
    throw InputError({"", what, "max_tracks"}, "must be 1 to 1000");
  if (!(max_step_px > 0 && max_step_px < 10000))
    throw InputError({"", what, "max_step_px"}, "must be a positive number of px");
  if (full_detection_every < 1 || full_detection_every > 1000)
    throw InputError({"", what, "full_detection_every"}, "must be 1 to 1000 frames");
  if (window_margin_px < 1 || window_margin_px > 200)
    throw InputError({"", what, "window_margin_px"}, "must be 1 to 200 px");
}

namespace {

struct Track {
  int id = 0;
  int age = 0;
  LampDetection last;         // its lamp in the last frame
  Vector2d velocity{0, 0};    // px a frame, of the lamp's centre
  double unsure = 0;          // px: the last change of velocity (the prediction's error)
  bool moving_known = false;  // velocity measured (two whole views of the lamp)
  Vector2d predicted() const { return last.centre_px + velocity; }
};

bool whole_view(const LampDetection& d) { return d.view != LampView::partial; }

PixelBox grown(const PixelBox& b, int by) { return {b.u0 - by, b.v0 - by, b.u1 + by, b.v1 + by}; }

PixelBox as_box(const std::array<int, 4>& b) { return {b[0], b[1], b[2], b[3]}; }

}  // namespace

struct LampTracker::Impl {
  LampDetector detector;
  LampTrackerOptions o;
  std::uint8_t threshold;
  std::vector<Track> tracks;       // oldest first
  std::vector<PixelBox> watched;   // border blobs of the last frame that were not lamps
  std::vector<int> pending_ended;  // from reset()
  int next_id = 1;
  int since_whole = 1 << 20;  // frames since the last frame read whole; huge: read the next whole
  std::vector<std::uint8_t> grey;
  mutable std::vector<std::pair<int, int>> covered;  // ring_unexplained: [a, b] along a side
  // The ring's left and right columns are read this many pixels apart: a third of the shortest
  // stretch of them a lamp can cover (LampDetector::border_chord_px), so that a lamp entering
  // there is seen by at least three of the pixels read.
  int column_every = 1;

  Impl(const CameraDescription& camera, const LampShapePrior& prior,
       const LampDetectorOptions& detector_options, const LampTrackerOptions& options)
      : detector(camera, prior, detector_options),
        o(options),
        threshold(static_cast<std::uint8_t>(detector_options.threshold)) {
    o.validate();
    const double third = detector.border_chord_px() / 3;
    column_every = third >= 1 ? static_cast<int>(std::min(third, 64.0)) : 1;
  }

  TrackedFrame process(const ImageView& image);
  // The windows of the next frame, or nothing when it must be read whole.
  std::optional<std::vector<PixelBox>> windows() const;
  // Something bright on the image's border ring outside every window: a lamp entering unseen.
  bool ring_unexplained(const ImageView& g, const std::vector<PixelBox>& boxes) const;
  // Gives the detections to the tracks; false when a track found no lamp (windowed frames: the
  // frame is then read whole, the verdict is the full detection's).
  bool associate(const LampDetections& found, bool windowed, TrackedFrame& out);
};

std::optional<std::vector<PixelBox>> LampTracker::Impl::windows() const {
  if (since_whole + 1 >= o.full_detection_every) return std::nullopt;
  // The ceiling moves as one under a translation: a track whose own motion is not measured yet
  // borrows the mean of the others'; with none, its window covers any allowed step.
  Vector2d mean{0, 0};
  int known = 0;
  double fastest = 0;
  for (const Track& t : tracks) {
    if (!t.moving_known) continue;
    mean += t.velocity;
    ++known;
    fastest = std::max(fastest, t.velocity.norm() + t.unsure);
  }
  if (known > 0) mean /= known;
  std::vector<PixelBox> boxes;
  for (const Track& t : tracks) {
    const Vector2d v = t.moving_known ? t.velocity : mean;
    const int margin =
        o.window_margin_px + static_cast<int>(std::ceil(t.moving_known ? t.unsure
                                                        : known > 0    ? 2 * o.window_margin_px
                                                                       : o.max_step_px));
    // Where the lamp was and where it goes: a lamp cut by the border shrinks or grows there.
    const PixelBox b = as_box(t.last.bbox);
    const int du = static_cast<int>(std::lround(v.x())), dv = static_cast<int>(std::lround(v.y()));
    boxes.push_back(grown({std::min(b.u0, b.u0 + du), std::min(b.v0, b.v0 + dv),
                           std::max(b.u1, b.u1 + du), std::max(b.v1, b.v1 + dv)},
                          margin));
  }
  const int step =
      o.window_margin_px + static_cast<int>(std::ceil(known > 0 ? fastest : o.max_step_px));
  for (const PixelBox& b : watched) boxes.push_back(grown(b, step));
  return boxes;
}

bool LampTracker::Impl::ring_unexplained(const ImageView& g,
                                         const std::vector<PixelBox>& boxes) const {
  const int w = g.width, h = g.height;
  const std::size_t stride = g.row_stride();
  // One side of the ring: `n` pixels from `first`, `step` apart in memory, at positions 0..n-1
  // along it, of which those at multiples of `every` are read. The parts inside a box are
  // explained; the rest is read until a bright pixel.
  auto side = [&](const std::uint8_t* first, std::size_t step, int n, auto box_span, int every) {
    covered.clear();
    for (const PixelBox& b : boxes)
      if (const auto span = box_span(b)) covered.push_back(*span);
    std::sort(covered.begin(), covered.end());
    int k = 0;
    auto dark_until = [&](int end) {
      for (k = (k + every - 1) / every * every; k < end; k += every)
        if (first[static_cast<std::size_t>(k) * step] >= threshold) return false;
      return true;
    };
    for (const auto& [a, b] : covered) {
      if (!dark_until(std::min(a, n))) return true;
      k = std::max(k, b + 1);
    }
    return !dark_until(n);
  };
  using Span = std::optional<std::pair<int, int>>;
  auto along_row = [&](int v) {
    return [v, w](const PixelBox& b) -> Span {
      if (b.v0 > v || b.v1 < v || b.u1 < 0 || b.u0 >= w) return std::nullopt;
      return std::make_pair(std::max(b.u0, 0), std::min(b.u1, w - 1));
    };
  };
  auto along_column = [&](int u) {
    return [u, h](const PixelBox& b) -> Span {
      if (b.u0 > u || b.u1 < u || b.v1 < 0 || b.v0 >= h) return std::nullopt;
      return std::make_pair(std::max(b.v0, 0), std::min(b.v1, h - 1));
    };
  };
  // The columns' pixels are a row apart: each is a read from memory. They are asked for at once,
  // before the rows are read, so that the reads overlap.
  for (int v = 0; v < h; v += column_every) {
    __builtin_prefetch(g.data + static_cast<std::size_t>(v) * stride);
    __builtin_prefetch(g.data + static_cast<std::size_t>(v) * stride + (w - 1));
  }
  return side(g.data, 1, w, along_row(0), 1) ||
         side(g.data + static_cast<std::size_t>(h - 1) * stride, 1, w, along_row(h - 1), 1) ||
         side(g.data, stride, h, along_column(0), column_every) ||
         side(g.data + (w - 1), stride, h, along_column(w - 1), column_every);
}

bool LampTracker::Impl::associate(const LampDetections& found, bool windowed, TrackedFrame& out) {
  std::vector<int> owner(found.lamps.size(), -1);  // detection -> track index
  std::vector<int> match_of(tracks.size(), -1);
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const Vector2d p = tracks[i].predicted();
    double best = o.max_step_px;
    for (std::size_t k = 0; k < found.lamps.size(); ++k) {
      const double d = (found.lamps[k].centre_px - p).norm();
      if (d <= best) {
        best = d;
        match_of[i] = static_cast<int>(k);
      }
    }
    // No lamp where the track's lamp should be (it left the view, shrank below the area filter,
    // went out), or an older track holds it (two blobs merged): the track ends.
    const int k = match_of[i];
    if (k >= 0 && owner[k] < 0) {
      owner[k] = static_cast<int>(i);
    } else {
      if (windowed) return false;
      match_of[i] = -1;
    }
  }
  std::vector<Track> kept;
  kept.reserve(tracks.size() + found.lamps.size());
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    Track& t = tracks[i];
    if (match_of[i] < 0) {
      out.ended.push_back(t.id);
      continue;
    }
    const LampDetection& d = found.lamps[match_of[i]];
    if (whole_view(d) && whole_view(t.last)) {
      const Vector2d v = d.centre_px - t.last.centre_px;
      t.unsure = t.moving_known ? (v - t.velocity).norm() : 0.0;
      t.velocity = v;
      t.moving_known = true;
    }
    t.last = d;
    ++t.age;
    owner[match_of[i]] = static_cast<int>(kept.size());
    kept.push_back(std::move(t));
  }
  tracks = std::move(kept);
  // Lamps no track claimed start new tracks.
  for (std::size_t k = 0; k < found.lamps.size(); ++k) {
    if (owner[k] >= 0 || static_cast<int>(tracks.size()) >= o.max_tracks) continue;
    Track t;
    t.id = next_id++;
    t.age = 1;
    t.last = found.lamps[k];
    owner[k] = static_cast<int>(tracks.size());
    tracks.push_back(std::move(t));
  }
  for (std::size_t k = 0; k < found.lamps.size(); ++k) {
    if (owner[k] < 0) continue;
    const Track& t = tracks[owner[k]];
    out.lamps.push_back({t.id, t.age, t.age == 1, found.lamps[k]});
  }
  std::sort(out.lamps.begin(), out.lamps.end(),
            [](const TrackedLamp& a, const TrackedLamp& b) { return a.track_id < b.track_id; });
  watched = found.border_blobs;
  return true;
}

TrackedFrame LampTracker::Impl::process(const ImageView& image) {
  check_image(image, detector.width(), detector.height(), {"", "image", ""});
  const ImageView g = grey_view(image, grey);
  TrackedFrame out;
  out.ended = std::move(pending_ended);
  pending_ended.clear();
  // Pixels a windowed attempt read before the frame had to be read whole still count.
  long tried = 0;
  if (const auto boxes = windows()) {
    tried = 2L * (g.width + g.height) - 4;  // the border ring
    if (!ring_unexplained(g, *boxes)) {
      const LampDetections found = detector.detect_in(g, *boxes);
      tried += found.pixels_read;
      // associate() leaves `out` as it was when it refuses a windowed frame.
      if (!found.spilled && associate(found, true, out)) {
        out.stats = found.stats;
        out.whole = false;
        out.pixels_read = tried;
        ++since_whole;
        return out;
      }
    }
  }
  const LampDetections found = detector.detect(g);
  associate(found, false, out);
  out.stats = found.stats;
  out.whole = true;
  out.pixels_read = tried + found.pixels_read;
  since_whole = 0;
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
  for (const auto& t : impl_->tracks) impl_->pending_ended.push_back(t.id);
  impl_->tracks.clear();
  impl_->watched.clear();
  impl_->since_whole = 1 << 20;
}

int LampTracker::live_tracks() const { return static_cast<int>(impl_->tracks.size()); }

}  // namespace lampnav::vision
