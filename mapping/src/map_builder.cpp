#include "lampnav/mapping/map_builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "drive_scale.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/core/parallel.hpp"
#include "lampnav/fusion/odometry_track.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/mapping/lamp_kinds.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "median.hpp"
#include "omni_choice.hpp"
#include "omni_ways.hpp"
#include "part_placement.hpp"
#include "view_jumps.hpp"

namespace lampnav::mapping {

namespace {

// The advice when the ceiling camera saw the lamps only at the border of its view.
const std::string kDriveUnderARow =
    "drive under the rows of lamps (in a wide corridor, up one row and back along the other)";

// Where a measured distance came from, for messages: the user's flag, or its place in the options.
ErrorContext where_given(const KnownDistance& d, std::size_t k) {
  return {"", d.given_as.empty() ? "distances[" + std::to_string(k) + "]" : d.given_as, ""};
}

}  // namespace

void MapBuildOptions::validate() const {
  mapper.validate();
  topology.validate();
  detector.validate();
  kinds.validate();
  if (probe_frames < 10)
    throw InputError({"map build options", "", "probe_frames"}, "must be at least 10");
  if (omni_views_for_ways < 0)
    throw InputError({"map build options", "", "omni_views_for_ways"}, "must not be negative");
  if (!(max_scale_change > 0 && max_scale_change < 0.5))
    throw InputError({"map build options", "", "max_scale_change"},
                     "must be above 0 and below 0.5");
  if (!(tape_sigma_m >= 0 && tape_sigma_m < 1))
    throw InputError({"map build options", "", "tape_sigma_m"}, "must be from 0 to 1 m");
  if (!(distance_tolerance_m >= 0 && distance_tolerance_m < 10))
    throw InputError({"map build options", "", "distance_tolerance_m"}, "must be from 0 to 10 m");
  for (std::size_t k = 0; k < distances.size(); ++k) {
    const KnownDistance& d = distances[k];
    const ErrorContext where = where_given(d, k);
    if (d.from.empty() || d.to.empty()) throw InputError(where, "names no lamp");
    if (d.from == d.to) throw InputError(where, "names one lamp twice");
    if (!(std::isfinite(d.metres) && d.metres > 0))
      throw InputError(where, "the distance must be a number of metres above 0");
  }
}

namespace {

// A detector that takes any bright blob from a thirtieth of a radian to three radians across
// (a 0.3 m wide lamp 9 m above the camera; one a metre across at 0.3 m), for learning what the
// building's lamps look like.
vision::LampShapePrior probe_prior() {
  vision::LampShapePrior p;
  p.rectangle = true;
  p.length = 1.0;
  p.width = 1.0;
  p.min_distance = 0.3;
  p.nominal_distance = 1.0;
  p.max_distance = 30.0;
  return p;
}

// A frame's lamps by a detector of each kind: a lamp seen whole is kept from the detector of its
// nearest kind (a blob of one kind may pass another's bounds); a cut one, measured with a kind's
// size, from the first detector (the most common kind) that saw it where no lamp kept lies.
std::vector<vision::LampDetection> detect_kinds(std::vector<vision::LampDetector>& detectors,
                                                const std::vector<vision::LampShapePrior>& kinds,
                                                const Image8& img) {
  if (detectors.size() == 1) return detectors.front().detect(img).lamps;
  std::vector<std::vector<vision::LampDetection>> by_kind;
  for (auto& d : detectors) by_kind.push_back(d.detect(img).lamps);
  std::vector<vision::LampDetection> out;
  std::vector<double> reach;  // a kept lamp's half width, normalized
  for (std::size_t k = 0; k < kinds.size(); ++k)
    for (const auto& d : by_kind[k])
      if (d.view == vision::LampView::full &&
          nearest_kind(kinds, d.length, d.width) == static_cast<int>(k)) {
        out.push_back(d);
        reach.push_back(0.5 * d.width);
      }
  for (std::size_t k = 0; k < kinds.size(); ++k)
    for (const auto& d : by_kind[k]) {
      if (d.view == vision::LampView::full) continue;
      bool near = false;
      for (std::size_t j = 0; j < out.size() && !near; ++j)
        near = (out[j].centre - d.centre).norm() < reach[j] + 0.5 * kinds[k].width;
      if (near) continue;
      out.push_back(d);
      reach.push_back(0.5 * kinds[k].width);
    }
  return out;
}

std::string metres(double m, int decimals = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f m", decimals, m);
  return buf;
}

std::string percent(double f, int decimals = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f %%", decimals, 100 * f);
  return buf;
}

// The scale that fits the measured distances best (least squares on the map's horizontal
// distances between the named lamps), after the checks of MapBuildOptions::distances.
double scale_for_distances(const graph::TopologicalMap& map, const MapBuildOptions& o,
                           const std::string& source, std::vector<std::string>& notes) {
  struct Pair {
    ErrorContext where;
    double map_m, measured_m;
  };
  std::vector<Pair> pairs;
  for (std::size_t k = 0; k < o.distances.size(); ++k) {
    const KnownDistance& d = o.distances[k];
    const ErrorContext where = where_given(d, k);
    const graph::Lamp* lamps[2] = {map.find_lamp(LampId(d.from)), map.find_lamp(LampId(d.to))};
    for (int e = 0; e < 2; ++e)
      if (!lamps[e])
        throw InputError(where, "no lamp \"" + (e ? d.to : d.from) + "\" in the map built from " +
                                    source +
                                    " (its lamp ids: `lampnav map render MAP --lamp-ids` of the "
                                    "map built without --distance)");
    const double m = (lamps[0]->xyz.head<2>() - lamps[1]->xyz.head<2>()).norm();
    if (m < 1e-6) throw InputError(where, "the two lamps are at one place in the map");
    pairs.push_back({where, m, d.metres});
  }
  double num = 0, den = 0, measured = 0;
  for (const Pair& p : pairs) {
    num += p.measured_m * p.map_m;
    den += p.map_m * p.map_m;
    measured += p.measured_m;
  }
  const double s = num / den;
  for (const Pair& p : pairs) {
    const double change = p.map_m / p.measured_m - 1;
    if (std::abs(p.measured_m / p.map_m - 1) > o.max_scale_change)
      throw InputError(p.where, "the map has these lamps " + metres(p.map_m) + " apart, " +
                                    percent(std::abs(change), 1) +
                                    (change > 0 ? " more" : " less") +
                                    " than measured; wheels are calibrated better than " +
                                    percent(o.max_scale_change, 1) +
                                    ": are these the lamps measured, and is the distance right?");
  }
  for (const Pair& p : pairs) {
    const double off = s * p.map_m - p.measured_m;
    if (pairs.size() > 1 && std::abs(off) > o.distance_tolerance_m + 3 * o.tape_sigma_m)
      throw InputError(p.where,
                       "disagrees with the other measured distances: scaled to fit "
                       "them all, the map has these lamps " +
                           metres(s * p.map_m) + " apart, " + metres(std::abs(off)) +
                           (off > 0 ? " more" : " less") + " than measured");
  }
  // Uncertainty of the scale from the tape alone: sigma / sqrt(sum of squared lengths).
  const double sigma = o.tape_sigma_m / std::sqrt(den);
  notes.push_back("scaled by " + std::to_string(pairs.size()) + " measured distance" +
                  (pairs.size() > 1 ? "s" : "") + " (" + metres(measured, 2) + " in all): the " +
                  "wheels had made the map " + percent(std::abs(1 / s - 1)) +
                  (s < 1 ? " larger" : " smaller") + " than the building (the tape's " +
                  metres(o.tape_sigma_m) + " leaves " + percent(sigma) + " of scale)");
  return s;
}

// The omni camera's lamps in the log's omni frames, at most `most` of them spread over the drive
// (none without an omni camera).
std::vector<OmniView> omni_views(const io::MissionLog& log, const std::string& source,
                                 const RobotDescription& robot,
                                 std::size_t most = std::numeric_limits<std::size_t>::max()) {
  const CameraDescription* cam = robot.find_camera("omni_camera");
  std::vector<const io::Logged<io::ImageFrame>*> all, frames;
  for (const auto& f : log.omni_images)
    if (f.value.frame_id == "omni_camera") all.push_back(&f);
  if (!cam || all.empty()) return {};
  if (all.size() <= most) {
    frames = std::move(all);
  } else {
    for (std::size_t k = 0; k < most; ++k) frames.push_back(all[k * all.size() / most]);
  }
  std::vector<OmniView> views(frames.size());
  std::vector<char> readable(frames.size(), 0);
  for_each_index(
      frames.size(), [&] { return vision::OmniLampDetector(*cam); },
      [&](vision::OmniLampDetector& detector, std::size_t i) {
        try {
          const Image8 img = io::decode_image(frames[i]->value.data, source);
          views[i] = {frames[i]->value.stamp, detector.detect(vision::ImageView::of(img))};
          readable[i] = 1;
        } catch (const std::exception&) {
          // an unreadable or foreign omni frame tells nothing: left out
        }
      });
  std::vector<OmniView> out;
  for (std::size_t i = 0; i < views.size(); ++i)
    if (readable[i]) out.push_back(std::move(views[i]));
  return out;
}

// Where each part of a drive after a carry starts in the map (the frame of the base: the first
// part that maps a lamp): each part mapped on its own, then put onto the lamps of the parts
// before it where they fit one place only. nullopt for the base, for the parts before it and for
// a part left out; a note for the user on each carry.
template <class Feed>
std::vector<std::optional<Pose2>> place_parts(
    const io::MissionLog& log, const std::string& source, const RobotDescription& robot,
    const MapBuildOptions& o, const std::vector<std::size_t>& starts, Feed& feed,
    const std::vector<const io::Logged<io::ImageFrame>*>& frames, std::vector<std::string>& notes,
    std::size_t& base) {
  const std::size_t parts = starts.size() - 1;
  std::vector<std::optional<Pose2>> out(parts);
  base = 0;
  std::vector<MappingResult> alone;
  for (std::size_t p = 0; p < parts && parts > 1; ++p) {
    LampMapper mapper(robot, o.mapper);
    feed(mapper, starts[p], starts[p + 1], false);
    alone.push_back(mapper.finish());
  }
  if (parts == 1) return out;
  PlacementOptions po;
  {
    // The ceiling camera's reach: half the tangent of its narrower half-angle.
    const CameraDescription& c = *robot.find_camera("ceiling_camera");
    const PinholeParameters k = vision::PinholeCamera::intrinsics(c);
    const double half =
        std::min({k.cx, c.width - k.cx, k.cy * k.fx / k.fy, (c.height - k.cy) * k.fx / k.fy});
    po.sure_per_height = 0.5 * half / k.fx;
    po.camera_height_m = c.mount.xyz.z();
  }
  const CameraDescription* omni_camera = robot.find_camera("omni_camera");
  std::optional<std::vector<OmniView>> omni;  // detected when first needed
  // The omni views taken while the frames [from, to) were.
  auto views_during = [&](std::size_t from, std::size_t to) {
    std::vector<const OmniView*> during;
    for (const OmniView& v : *omni)
      if (v.stamp >= frames[from]->value.stamp && v.stamp <= frames[to - 1]->value.stamp)
        during.push_back(&v);
    return during;
  };
  auto seconds = [&](std::size_t i) {
    return to_seconds(frames[i]->value.stamp - frames.front()->value.stamp);
  };
  const std::size_t first_note = notes.size();
  // A part with fewer lamps than a placement needs shared can take no part after it.
  const std::size_t first_lamps = alone[0].lamps.size();
  while (base + 1 < parts && alone[base].lamps.size() < static_cast<std::size_t>(po.min_shared))
    ++base;
  if (base > 0) {
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "the ceiling view jumped %.1f s into the drive as no driving could make it (the "
                  "robot was carried); the drive before it mapped %s, so the map starts where "
                  "the robot was put down",
                  seconds(starts[base]),
                  first_lamps == 0
                      ? "no lamp"
                      : (std::to_string(first_lamps) + (first_lamps == 1 ? " lamp" : " lamps") +
                         ", too few to join the rest to")
                            .c_str());
    notes.push_back(buf);
  }
  std::vector<MappedLamp> lamps = alone[base].lamps;
  std::vector<KeyframePose> path = alone[base].keyframes;
  for (std::size_t p = base + 1; p < parts; ++p) {
    const MappingResult& part = alone[p];
    Placement placed = place_part({&lamps, &path}, {&part.lamps, &part.keyframes}, po);
    std::string told;  // how the omni camera told places alike apart
    if (placed.fitting > 1 && omni_camera && !OmniChoiceOptions{}.tries(placed.fits.size())) {
      told = " (too many for the omni camera's views to be tried)";
    } else if (placed.fitting >= 1 && omni_camera) {
      if (!omni) omni = omni_views(log, source, robot);
      // The map so far holds the parts placed before this one: their views count as well.
      std::vector<const OmniView*> before;
      for (std::size_t q = base; q < p; ++q)
        if (q == base || out[q]) {
          const auto v = views_during(starts[q], starts[q + 1]);
          before.insert(before.end(), v.begin(), v.end());
        }
      // The places that fit are weighed against those that fit but for one lamp (failed, or
      // missed by one drive): the views must prefer the one taken to them as well.
      std::vector<PlacementFit> weighed = placed.fits;
      std::size_t near = 0;
      if (OmniChoiceOptions{}.tries(placed.fits.size() + placed.near_fits.size())) {
        near = placed.near_fits.size();
        weighed.insert(weighed.end(), placed.near_fits.begin(), placed.near_fits.end());
      }
      const OmniChoice c =
          choose_by_omni({&lamps, &path}, {&part.lamps, &part.keyframes}, weighed, before,
                         views_during(starts[p], starts[p + 1]), *omni_camera);
      char also[64] = "";
      if (near > 0) std::snprintf(also, sizeof also, " (and %zu more but for one lamp)", near);
      char buf[400] = "";
      if (c.chosen && *c.chosen >= placed.fits.size()) {
        // The views prefer a place that one lamp contradicts: neither is taken.
        placed.motion.reset();
        std::snprintf(buf, sizeof buf,
                      " (but the omni camera's %d views fit best a place where one lamp "
                      "contradicts it)",
                      c.views);
      } else if (c.chosen) {
        placed.motion = placed.fits[*c.chosen].motion;
        placed.shared = placed.fits[*c.chosen].shared;
        if (placed.fitting == 1 && near == 0)
          std::snprintf(buf, sizeof buf,
                        " at one place only, and the omni camera's %d views miss %d lamps with "
                        "it there (each part's own lamps alone: %d)",
                        c.views, c.fewest_missed, c.own_missed);
        else if (placed.fitting == 1)
          std::snprintf(buf, sizeof buf,
                        " at one place only%s, and the omni camera's %d views miss %d lamps with "
                        "it there (each part's own lamps alone: %d), and at any of the others at "
                        "least %d more",
                        also, c.views, c.fewest_missed, c.own_missed, c.least_extra);
        else
          std::snprintf(buf, sizeof buf,
                        "; of %d places its lamps fit alike%s, the omni camera's %d views miss %d "
                        "lamps at this one, and at any other at least %d more",
                        placed.fitting, also, c.views, c.fewest_missed, c.least_extra);
      } else if (c.views > 0 && !c.explains) {
        // The one place (or the likeliest of several) leaves lamps in view that the views do
        // not show: the part may lie where the drive before it never went.
        placed.motion.reset();
        std::snprintf(buf, sizeof buf,
                      " (but the omni camera's %d views miss %d lamps more %s than each part's "
                      "own lamps alone: it may lie where the drive before it never went)",
                      c.views, c.joined_extra,
                      placed.fitting == 1 ? "with it there" : "at the likeliest");
      } else if (c.views > 0) {
        // Where one place fits and the views cannot tell it from those one lamp away, a lamp
        // failed or missed decided it, not what was seen: it is not taken.
        if (placed.fitting == 1) {
          placed.motion.reset();
          std::snprintf(buf, sizeof buf,
                        " (but %zu more places fit it but for one lamp, and the omni camera's %d "
                        "views do not tell them apart: they miss %d lamps at the best, and only "
                        "%d more at the next)",
                        near, c.views, c.fewest_missed, c.least_extra);
        } else {
          char more[80] = "";
          if (near > 0)
            std::snprintf(more, sizeof more, ", or from %zu more that fit but for one lamp", near);
          std::snprintf(buf, sizeof buf,
                        " (nor do the omni camera's %d views tell them apart%s: they miss %d "
                        "lamps at the best, and only %d more at the next)",
                        c.views, more, c.fewest_missed, c.least_extra);
        }
      }
      told = buf;
    }
    if (o.keep_larger_part && !placed.motion && part.lamps.size() > lamps.size()) {
      // A part that cannot join the map so far and maps more lamps than it becomes the base:
      // of two maps that cannot be joined, the larger is kept. The lamp SLAM takes the parts in
      // time order, so the drive before it is left out, not put onto it.
      char fit[80], buf[800];
      if (placed.fitting == 0)
        std::snprintf(fit, sizeof fit, "fit nowhere on");
      else if (placed.fitting == 1)
        std::snprintf(fit, sizeof fit, "fit one place of");
      else
        std::snprintf(fit, sizeof fit, "fit %d places alike of", placed.fitting);
      std::snprintf(
          buf, sizeof buf,
          "the ceiling view jumped %.1f s into the drive as no driving could make it (the "
          "robot was carried), and its %zu lamps after it, to %.1f s, %s the %zu mapped "
          "before it%s: the map is built from the drive after it, starting where the "
          "robot was put down, and the drive before it is left out; map that from a "
          "drive of its own, or drive there without lifting the robot",
          seconds(starts[p]), part.lamps.size(), seconds(starts[p + 1] - 1), fit, lamps.size(),
          told.c_str());
      notes.resize(first_note);
      notes.push_back(buf);
      std::fill(out.begin(), out.end(), std::nullopt);
      base = p;
      lamps = part.lamps;
      path = part.keyframes;
      continue;
    }
    char head[200], tail[900];
    std::snprintf(head, sizeof head,
                  "the ceiling view jumped %.1f s into the drive as no driving could make it (the "
                  "robot was carried): the drive after it, to %.1f s,",
                  seconds(starts[p]), seconds(starts[p + 1] - 1));
    if (placed.motion && !part.keyframes.empty()) {
      const Pose2& T = *placed.motion;
      out[p] = T * part.keyframes.front().pose;
      for (MappedLamp l : part.lamps) {
        l.xyz.head<2>() = T.transform_from(l.xyz.head<2>());
        l.yaw = wrap_angle(l.yaw + T.yaw());
        lamps.push_back(l);
      }
      const int n = static_cast<int>(part.keyframes.size());
      for (int k = po.end_keyframes; k + po.end_keyframes < n; ++k)
        path.push_back({part.keyframes[k].stamp, T * part.keyframes[k].pose,
                        part.keyframes[k].dead_reckoned, part.keyframes[k].travel_m});
      // Where the robot was put down, in the map's frame: whoever carried it can check.
      std::snprintf(tail, sizeof tail,
                    " is in the map, put down at (%.1f, %.1f) facing %.0f deg: %d of its lamps "
                    "fall on lamps mapped before it%s",
                    out[p]->x(), out[p]->y(), out[p]->yaw() * 180 / M_PI, placed.shared,
                    told.empty() ? " at one place only" : told.c_str());
    } else if (placed.fitting == 0) {
      std::snprintf(tail, sizeof tail,
                    " is not in the map: its %zu lamps fit nowhere on the %zu mapped before it "
                    "(too few seen by both); map it from a drive of its own, or drive there "
                    "without lifting the robot",
                    part.lamps.size(), lamps.size());
    } else {
      std::string where;
      for (std::size_t k = 0; k < std::min<std::size_t>(4, placed.fits.size()); ++k) {
        const Pose2& T = placed.fits[k].motion;
        const Pose2 at = part.keyframes.empty() ? T : T * part.keyframes.front().pose;
        char buf[80];
        std::snprintf(buf, sizeof buf, "%s(%.1f, %.1f) facing %.0f deg", where.empty() ? "" : ", ",
                      at.x(), at.y(), at.yaw() * 180 / M_PI);
        where += buf;
      }
      if (placed.fitting == 1)
        std::snprintf(tail, sizeof tail,
                      " is not in the map: its lamps fit one place of the map before it (put "
                      "down at %s)%s; drive there without lifting the robot",
                      where.c_str(), told.c_str());
      else
        std::snprintf(tail, sizeof tail,
                      " is not in the map: its lamps fit %d places of the map before it alike (a "
                      "regular building; put down at %s%s)%s; drive there without lifting the "
                      "robot",
                      placed.fitting, where.c_str(), placed.fitting > 4 ? ", ..." : "",
                      told.c_str());
    }
    notes.push_back(std::string(head) + tail);
  }
  return out;
}

}  // namespace

DriveLamps map_drive_lamps(const io::MissionLog& log, const std::string& source,
                           const RobotDescription& robot, const MapBuildOptions& o,
                           const std::function<void(double)>& progress) {
  o.validate();
  const CameraDescription* cam = robot.find_camera("ceiling_camera");
  if (!cam)
    throw InputError({source, "robot.json", "cameras"},
                     "the robot has no camera named \"ceiling_camera\": the map is built from "
                     "its lamps");
  std::vector<const io::Logged<io::ImageFrame>*> frames;
  for (const auto& f : log.ceiling_images)
    if (f.value.frame_id == "ceiling_camera") frames.push_back(&f);
  if (frames.empty())
    throw InputError({source, io::topics::kCeilingImage, ""},
                     "the log holds no ceiling camera frames: the map is built from them");
  if (log.wheels.size() < 2)
    throw InputError({source, io::topics::kWheels, ""},
                     "the log holds no wheel readings: the drive cannot be followed");
  std::sort(frames.begin(), frames.end(),
            [](const auto* a, const auto* b) { return a->value.stamp < b->value.stamp; });

  DriveLamps out;
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  // 1. The lamps' look: full blobs from frames spread over the drive, at unit distance, grouped
  // into the building's kinds of lamp.
  {
    vision::LampDetectorOptions probe_options = o.detector;
    probe_options.max_shape_error = 0.95;
    vision::LampDetector probe(*cam, probe_prior(), probe_options);
    std::vector<LampLook> looks;
    std::size_t cut = 0, probed = 0;  // lamps seen cut by the border, in the frames probed
    const std::size_t step = std::max<std::size_t>(1, frames.size() / o.probe_frames);
    for (std::size_t i = 0; i < frames.size(); i += step) {
      try {
        const Image8 img = io::decode_image(frames[i]->value.data, source);
        ++probed;
        for (const auto& d : probe.detect(img).lamps) {
          if (d.view == vision::LampView::full) looks.push_back({d.length, d.width});
          cut += d.view != vision::LampView::full;
        }
      } catch (const std::exception&) {
        // an unreadable frame is counted in the full pass
      }
    }
    // Lamps only ever cut by the border: the camera went beside them, not under them (a wide
    // corridor's two rows, driven down the middle between them).
    if (looks.empty() && cut > 0)
      throw JobFailed(source + ": no lamp was seen whole in " + std::to_string(frames.size()) +
                      " ceiling frames, only lamps cut by the image's border (" +
                      std::to_string(cut) + " in " + std::to_string(probed) +
                      " frames looked at): the camera passed beside the lamps, not under them; " +
                      kDriveUnderARow);
    if (looks.empty())
      throw JobFailed(source + ": no lamp was seen whole in " + std::to_string(frames.size()) +
                      " ceiling frames: there is nothing to map");
    out.kinds = lamp_kinds(looks, o.kinds);
    out.prior = out.kinds.front();
  }

  // 2. Every frame through the detector (decoding and detecting on every core, a detector of
  // each kind each), then, with the wheels in time order, the lamp SLAM.
  std::vector<std::vector<vision::LampDetection>> detected(frames.size());
  std::vector<char> unreadable(frames.size(), 0);
  for_each_index(
      frames.size(),
      [&] {
        std::vector<vision::LampDetector> detectors;
        for (const auto& kind : out.kinds) detectors.emplace_back(*cam, kind, o.detector);
        return detectors;
      },
      [&](std::vector<vision::LampDetector>& detectors, std::size_t i) {
        try {
          detected[i] =
              detect_kinds(detectors, out.kinds, io::decode_image(frames[i]->value.data, source));
        } catch (const std::exception&) {
          unreadable[i] = 1;
        }
      });
  if (progress) progress(0.9);
  out.detect_seconds = since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const auto& wheels = log.wheels;
  // Where the view jumps (the robot carried): the parts between are mapped apart, each joined to
  // the map of the drive before it only where its lamps fit one place.
  std::vector<std::size_t> starts{0};
  {
    // The robot's pose by its wheels at each frame, between the readings on either side of it.
    fusion::OdometryTrack dead_reckoned(robot.semi_axis, Duration::max());
    for (std::size_t w = 0; w < wheels.size(); ++w)
      dead_reckoned.add(wheels[w].value.stamp,
                        w > 0 ? wheels[w].value.left - wheels[w - 1].value.left : 0.0,
                        w > 0 ? wheels[w].value.right - wheels[w - 1].value.right : 0.0);
    std::vector<ViewFrame> view(frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      view[i].stamp = frames[i]->value.stamp;
      view[i].wheels = dead_reckoned.at(view[i].stamp);
      view[i].lamps = unreadable[i] ? nullptr : &detected[i];
    }
    for (const std::size_t jump : view_jumps(view, *cam)) starts.push_back(jump);
  }
  const std::size_t parts = starts.size();
  starts.push_back(frames.size());
  // Frames [from, to) into a mapper, with the wheels from the last reading before them on.
  auto feed = [&](LampMapper& mapper, std::size_t from, std::size_t to, bool count) {
    std::size_t w = 0;
    while (w + 1 < wheels.size() && wheels[w + 1].value.stamp <= frames[from]->value.stamp) ++w;
    for (std::size_t i = from; i < to; ++i) {
      const Stamp t = frames[i]->value.stamp;
      for (; w < wheels.size() && wheels[w].value.stamp <= t; ++w)
        mapper.wheels(wheels[w].value.stamp, wheels[w].value.left, wheels[w].value.right);
      if (count) ++out.frames;
      if (unreadable[i]) {
        if (count) ++out.unreadable_frames;
        continue;
      }
      if (count)
        for (const auto& d : detected[i]) {
          out.lamps_seen_whole += d.view == vision::LampView::full;
          out.lamps_seen_cut += d.view != vision::LampView::full;
        }
      mapper.ceiling(t, detected[i]);
    }
  };
  MapBuildOptions learnt = o;
  learnt.mapper.kinds = out.kinds;
  std::size_t base = 0;
  const std::vector<std::optional<Pose2>> carried_to =
      place_parts(log, source, robot, learnt, starts, feed, frames, out.notes, base);
  LampMapper mapper(robot, learnt.mapper);
  for (std::size_t p = base; p < parts; ++p) {
    if (p > base && !carried_to[p]) continue;
    if (p > base) mapper.carried(*carried_to[p]);
    feed(mapper, starts[p], starts[p + 1], true);
  }
  out.mapped = mapper.finish();
  out.slam_seconds = since(t1);
  out.from_start = base == 0;
  if (o.start && base > 0) {
    out.notes.push_back(
        "--start is where the drive started, which is not in the map: the map's frame is where "
        "the robot was put down");
  } else if (o.start) {
    // The whole drive and its lamps moved so that the start is where the user says.
    const Pose2& T = *o.start;
    for (auto& l : out.mapped.lamps) {
      l.xyz.head<2>() = T.transform_from(l.xyz.head<2>());
      l.yaw = wrap_angle(l.yaw + T.yaw());
    }
    for (auto& k : out.mapped.keyframes) k.pose = T * k.pose;
  }
  if (!out.mapped.keyframes.empty()) out.travel_m = out.mapped.keyframes.back().travel_m;
  if (out.travel_m < 1.0)
    throw JobFailed(source + ": the robot moved " + std::to_string(out.travel_m) +
                    " m: a map needs a drive under the lamps");
  if (out.mapped.lamps.empty())
    throw JobFailed(source + ": no lamp was seen from enough places to be mapped (" +
                    std::to_string(out.lamps_seen_whole) + " sightings in " +
                    std::to_string(out.frames) + " frames)");

  if (out.unreadable_frames)
    out.notes.push_back(std::to_string(out.unreadable_frames) +
                        " ceiling frames could not be decoded and were skipped");
  // On a drive under the lamps, at most about as many sightings are cut by the border (lamps
  // coming into view and leaving it) as whole: 0.2 to 1.3 times on the office's routes (its lamps
  // as they are, turned across the corridors, to one side, in two rows). Far more cut means the
  // camera went beside the lamps (a wide corridor's rows, driven between them), and the map holds
  // only those it happened to pass under.
  if (out.lamps_seen_cut > 4 * out.lamps_seen_whole) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%zu %s mapped along %.0f m", out.mapped.lamps.size(),
                  out.mapped.lamps.size() == 1 ? "lamp was" : "lamps were", out.travel_m);
    out.notes.push_back("most lamps were seen cut by the image's border (" +
                        std::to_string(out.lamps_seen_cut) + " sightings, " +
                        std::to_string(out.lamps_seen_whole) + " whole): the camera passed " +
                        "beside the lamps, not under them, and " + buf + "; " + kDriveUnderARow);
  }
  return out;
}

MapBuildResult build_map(const io::MissionLog& log, const std::string& source,
                         const RobotDescription& robot, const MapBuildOptions& o,
                         const std::vector<PlaceName>& names,
                         const std::function<void(double)>& progress) {
  MapBuildResult out;
  static_cast<DriveLamps&>(out) = map_drive_lamps(log, source, robot, o, progress);
  // 3. Places and connections, with the lamps the omni camera saw around the drive (ways out it
  // did not take).
  std::vector<Eigen::Vector2d> seen;
  const CameraDescription* omni_camera = robot.find_camera("omni_camera");
  if (omni_camera && o.topology.way_min_lamps > 0) {
    std::vector<double> heights;
    std::vector<Eigen::Vector3d> centres;
    for (const auto& l : out.mapped.lamps) {
      heights.push_back(l.xyz.z());
      centres.push_back(l.xyz);
    }
    seen = lamps_seen_around(
        omni_views(log, source, robot, static_cast<std::size_t>(o.omni_views_for_ways)),
        out.mapped.keyframes, *omni_camera, median(heights), centres, OmniLampsOptions{});
  }
  out.map = build_topology(out.mapped, o.topology, names, &out.topology, seen);
  if (out.map.edge_count() == 0)
    throw JobFailed(source +
                    ": the drive has no straight stretch long enough to make a "
                    "corridor; " +
                    std::to_string(out.mapped.lamps.size()) + " lamps were mapped but no places");
  if (!o.distances.empty()) {
    // The places are found again on the scaled lamps (the ids the distances named stay: a
    // scale of a fraction of a percent moves no lamp from its place or order).
    std::vector<std::string> scale_notes;
    out.scale = scale_for_distances(out.map, o, source, scale_notes);
    const Eigen::Vector2d about = o.start ? o.start->translation() : Eigen::Vector2d::Zero();
    scale_drive(out.mapped, out.scale, about, robot.find_camera("ceiling_camera")->mount.xyz.z());
    out.travel_m *= out.scale;
    for (auto& p : seen) p = about + out.scale * (p - about);
    out.map = build_topology(out.mapped, o.topology, names, &out.topology, seen);
    out.topology.notes.insert(out.topology.notes.end(), scale_notes.begin(), scale_notes.end());
  }
  // The drive's notes (frames skipped, a jump of the view) first, then the places'.
  out.notes.insert(out.notes.end(), out.topology.notes.begin(), out.topology.notes.end());
  if (out.mapped.revisits == 0)
    out.notes.push_back(
        "the drive never came back to a lamp it had left: no loop closed, so "
        "the drift of the wheels is not taken out (drive a loop and back)");
  if (o.distances.empty() && out.travel_m >= 20)
    out.notes.push_back(
        "the map's scale is the wheels' calibration (0.1 % off is 10 cm in 100 m): measure the "
        "distance between two lamps far apart and build again with --distance FROM,TO,METRES");
  return out;
}

}  // namespace lampnav::mapping
