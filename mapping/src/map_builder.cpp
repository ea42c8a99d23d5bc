#include "lampnav/mapping/map_builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/core/parallel.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "median.hpp"

namespace lampnav::mapping {

void MapBuildOptions::validate() const {
  mapper.validate();
  topology.validate();
  detector.validate();
  if (probe_frames < 10)
    throw InputError({"map build options", "", "probe_frames"}, "must be at least 10");
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
  // 1. The lamps' look: full blobs from frames spread over the drive, at unit distance.
  {
    vision::LampDetectorOptions probe_options = o.detector;
    probe_options.max_shape_error = 0.95;
    vision::LampDetector probe(*cam, probe_prior(), probe_options);
    std::vector<double> lengths, widths;
    int rectangles = 0, discs = 0;
    const std::size_t step = std::max<std::size_t>(1, frames.size() / o.probe_frames);
    for (std::size_t i = 0; i < frames.size(); i += step) {
      try {
        const Image8 img = io::decode_image(frames[i]->value.data, source);
        for (const auto& d : probe.detect(img).lamps) {
          if (d.view != vision::LampView::full) continue;
          lengths.push_back(d.length);
          widths.push_back(d.width);
          (d.length > 1.5 * d.width ? rectangles : discs) += 1;
        }
      } catch (const std::exception&) {
        // an unreadable frame is counted in the full pass
      }
    }
    if (lengths.empty())
      throw JobFailed(source + ": no lamp was seen whole in " + std::to_string(frames.size()) +
                      " ceiling frames: there is nothing to map");
    // The lamps of the most common kind give the prior (the detector knows one kind).
    std::vector<double> ls, ws;
    for (std::size_t k = 0; k < lengths.size(); ++k) {
      const bool rect = lengths[k] > 1.5 * widths[k];
      if (rect == (rectangles >= discs)) {
        ls.push_back(lengths[k]);
        ws.push_back(widths[k]);
      }
    }
    out.prior.rectangle = rectangles >= discs;
    out.prior.length = median(ls);
    out.prior.width = out.prior.rectangle ? median(ws) : out.prior.length;
    out.prior.min_distance = 0.7;  // lamps up to 30 % nearer or 40 % further than most
    out.prior.nominal_distance = 1.0;
    out.prior.max_distance = 1.4;
  }

  // 2. Every frame through the detector (decoding and detecting on every core, a detector each),
  // then, with the wheels in time order, the lamp SLAM.
  std::vector<std::vector<vision::LampDetection>> detected(frames.size());
  std::vector<char> unreadable(frames.size(), 0);
  for_each_index(
      frames.size(), [&] { return vision::LampDetector(*cam, out.prior, o.detector); },
      [&](vision::LampDetector& detector, std::size_t i) {
        try {
          detected[i] = detector.detect(io::decode_image(frames[i]->value.data, source)).lamps;
        } catch (const std::exception&) {
          unreadable[i] = 1;
        }
      });
  if (progress) progress(0.9);
  out.detect_seconds = since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  LampMapper mapper(robot, o.mapper);
  std::size_t w = 0;
  const auto& wheels = log.wheels;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Stamp t = frames[i]->value.stamp;
    for (; w < wheels.size() && wheels[w].value.stamp <= t; ++w)
      mapper.wheels(wheels[w].value.stamp, wheels[w].value.left, wheels[w].value.right);
    ++out.frames;
    if (unreadable[i]) {
      ++out.unreadable_frames;
      continue;
    }
    for (const auto& d : detected[i]) out.lamps_seen_whole += d.view == vision::LampView::full;
    mapper.ceiling(t, detected[i]);
  }
  out.mapped = mapper.finish();
  out.slam_seconds = since(t1);
  if (o.start) {
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
  return out;
}

MapBuildResult build_map(const io::MissionLog& log, const std::string& source,
                         const RobotDescription& robot, const MapBuildOptions& o,
                         const std::vector<PlaceName>& names,
                         const std::function<void(double)>& progress) {
  MapBuildResult out;
  static_cast<DriveLamps&>(out) = map_drive_lamps(log, source, robot, o, progress);
  // 3. Places and connections.
  out.map = build_topology(out.mapped, o.topology, names, &out.topology);
  if (out.map.edge_count() == 0)
    throw JobFailed(source +
                    ": the drive has no straight stretch long enough to make a "
                    "corridor; " +
                    std::to_string(out.mapped.lamps.size()) + " lamps were mapped but no places");
  out.notes = out.topology.notes;
  if (out.mapped.revisits == 0)
    out.notes.push_back(
        "the drive never came back to a lamp it had left: no loop closed, so "
        "the drift of the wheels is not taken out (drive a loop and back)");
  if (out.unreadable_frames)
    out.notes.push_back(std::to_string(out.unreadable_frames) +
                        " ceiling frames could not be decoded and were skipped");
  return out;
}

}  // namespace lampnav::mapping
