// Ceiling-frame lamp detection and tracking on 352x288 frames of a simulated corridor drive, side
// by side with OpenCV's SimpleBlobDetector and ViSP's vpDot2::searchDotsInArea on the same frames.
// Target (issue 4): detection plus tracking at most 200 us per frame on one core; issue 8 adds
// 640x480 frames of the same drive and wants ours at least 10 times faster than SimpleBlobDetector.
// Omnidirectional lamp detection on 1024x1024 museum frames: ours (connected components) against
// paper 1's pipeline as published (threshold, dilation, Canny, contours) on OpenCV.

#include <benchmark/benchmark.h>

#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImage.h>
#include <array>
#include <map>
#include <opencv2/features2d.hpp>
#include <random>

#include "cdr_writer.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/lamp_tracker.hpp"
#include "lampnav/vision/omni_detector.hpp"
#include "paper_omni_pipeline.hpp"

namespace {

using namespace lampnav;

// The drive along C1 seen by the ceiling camera of robot.json (352x288), or by the same camera at
// 640x480 (focal length and centre scaled with the width).
struct Frames {
  RobotDescription robot;
  std::vector<Image8> images;
  double scale = 1;  // pixel scale against 352x288
  explicit Frames(int width) {
    const std::string src = LAMPNAV_SOURCE_DIR;
    robot = read_robot_description(src + "/maps/robots/pioneer.json");
    for (auto& c : robot.cameras) {
      if (c.name != "ceiling_camera" || width == c.width) continue;
      scale = static_cast<double>(width) / c.width;
      c.pinhole.fx *= scale;
      c.pinhole.fy *= scale;
      c.width = width;
      c.height = width * 3 / 4;
      c.pinhole.cx = 0.5 * (c.width - 1);
      c.pinhole.cy = 0.5 * (c.height - 1);
    }
    const auto map = graph::read_map(src + "/maps/office_floor.geojson").map;
    const sim::CeilingRenderer renderer(*robot.find_camera("ceiling_camera"), {});
    const graph::Node& c1 = *map.find_node("C1");
    const Eigen::Vector2d dir = c1.axis->direction();
    std::mt19937_64 rng(1);
    // 0.5 m/s at 10 Hz along C1, the default floor bumps.
    std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
    for (double s = 0.5; s < c1.axis->length() - 0.5; s += 0.05) {
      const Pose2 pose(c1.axis->point_at(s), std::atan2(dir.y(), dir.x()));
      images.push_back(renderer.render(pose, {bump(rng), bump(rng)},
                                       map.lamps_within(pose.translation(), 5.0), rng));
    }
  }
  const CameraDescription& camera() const { return *robot.find_camera("ceiling_camera"); }
};

const Frames& frames(int width) {
  static std::map<int, Frames> cache;
  auto it = cache.find(width);
  if (it == cache.end()) it = cache.emplace(width, Frames(width)).first;
  return it->second;
}

void BM_LampDetector(benchmark::State& state) {
  const Frames& f = frames(static_cast<int>(state.range(0)));
  vision::LampDetector detector(f.camera(), vision::LampShapePrior{});
  std::size_t i = 0, lamps = 0;
  for (auto _ : state) {
    const auto d = detector.detect(f.images[i++ % f.images.size()]);
    lamps += d.lamps.size();
    benchmark::DoNotOptimize(d);
  }
  state.counters["lamps_per_frame"] = static_cast<double>(lamps) / state.iterations();
}
BENCHMARK(BM_LampDetector)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);

// Detection plus tracking, frames in driving order: windowed (the default: a frame read whole
// every 10, or when the windows cannot vouch for it), or every frame read whole.
void detect_and_track(benchmark::State& state, int full_detection_every) {
  const Frames& f = frames(static_cast<int>(state.range(0)));
  vision::LampTrackerOptions o;
  o.full_detection_every = full_detection_every;
  vision::LampTracker tracker(f.camera(), vision::LampShapePrior{}, {}, o);
  std::size_t i = 0, whole = 0;
  double pixels = 0;
  for (auto _ : state) {
    if (i % f.images.size() == 0) tracker.reset();  // the drive starts again
    const auto t = tracker.process(f.images[i++ % f.images.size()]);
    whole += t.whole ? 1 : 0;
    pixels += static_cast<double>(t.pixels_read);
    benchmark::DoNotOptimize(t);
  }
  const double frame = static_cast<double>(f.images.front().width) * f.images.front().height;
  state.counters["whole_frames"] = static_cast<double>(whole) / state.iterations();
  state.counters["pixels_read"] = pixels / frame / state.iterations();
}

void BM_LampDetectAndTrack(benchmark::State& state) {
  detect_and_track(state, vision::LampTrackerOptions{}.full_detection_every);
}
BENCHMARK(BM_LampDetectAndTrack)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);
// Two laps of the drive exactly (680 frames): the run that instruction counts are taken from,
// the same frames in every program compared (docs/performance.md):
//   valgrind --tool=callgrind --toggle-collect='lampnav::vision::LampTracker::process*'
//   build/bench/vision_bench --benchmark_filter='BM_LampDetectAndTrackTwoLaps/352'
void BM_LampDetectAndTrackTwoLaps(benchmark::State& state) { BM_LampDetectAndTrack(state); }
BENCHMARK(BM_LampDetectAndTrackTwoLaps)->Arg(352)->Arg(640)->Iterations(680);

void BM_LampDetectAndTrackWholeFrames(benchmark::State& state) { detect_and_track(state, 1); }
BENCHMARK(BM_LampDetectAndTrackWholeFrames)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);

// OpenCV's SimpleBlobDetector on the same frames, bright blobs of a lamp's area. `thresholds`:
// 1 gives it our single threshold (its fastest use); 18 is its own default sweep (50 to 220 in
// steps of 10, a blob kept when two thresholds agree), the way it is meant to be used.
void simple_blob_detector(benchmark::State& state, bool sweep) {
  const Frames& f = frames(static_cast<int>(state.range(0)));
  cv::SimpleBlobDetector::Params p;
  p.filterByColor = true;
  p.blobColor = 255;
  if (!sweep) {
    p.minThreshold = 128;
    p.maxThreshold = 129;
    p.thresholdStep = 10;
    p.minRepeatability = 1;
  }
  p.filterByArea = true;
  p.minArea = static_cast<float>(2500 * f.scale * f.scale);
  p.maxArea = static_cast<float>(12000 * f.scale * f.scale);
  p.filterByCircularity = false;
  p.filterByConvexity = false;
  p.filterByInertia = false;
  const auto detector = cv::SimpleBlobDetector::create(p);
  std::size_t i = 0, found = 0;
  std::vector<cv::KeyPoint> keypoints;
  for (auto _ : state) {
    const Image8& img = f.images[i++ % f.images.size()];
    const cv::Mat m(img.height, img.width, CV_8UC1, const_cast<std::uint8_t*>(img.pixels.data()));
    detector->detect(m, keypoints);
    found += keypoints.size();
  }
  state.counters["lamps_per_frame"] = static_cast<double>(found) / state.iterations();
}

void BM_OpenCvSimpleBlobDetector(benchmark::State& state) { simple_blob_detector(state, false); }
BENCHMARK(BM_OpenCvSimpleBlobDetector)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);

void BM_OpenCvSimpleBlobDetectorSweep(benchmark::State& state) {
  simple_blob_detector(state, true);
}
BENCHMARK(BM_OpenCvSimpleBlobDetectorSweep)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);

void BM_VispSearchDotsInArea(benchmark::State& state) {
  const Frames& f = frames(static_cast<int>(state.range(0)));
  vpDot2 model;
  model.setGraphics(false);
  model.setGrayLevelMin(128);
  model.setGrayLevelMax(255);
  model.setEllipsoidShapePrecision(0);
  model.setSizePrecision(0.5);
  model.setWidth(150 * f.scale);
  model.setHeight(38 * f.scale);
  model.setArea(5700 * f.scale * f.scale);
  std::size_t i = 0, found = 0;
  for (auto _ : state) {
    Image8& img = const_cast<Image8&>(f.images[i++ % f.images.size()]);
    const vpImage<unsigned char> I(img.pixels.data(), static_cast<unsigned>(img.height),
                                   static_cast<unsigned>(img.width), false);
    std::list<vpDot2> dots;
    model.searchDotsInArea(I, 0, 0, I.getWidth(), I.getHeight(), dots);
    found += dots.size();
  }
  state.counters["lamps_per_frame"] = static_cast<double>(found) / state.iterations();
}
BENCHMARK(BM_VispSearchDotsInArea)->Arg(352)->Arg(640)->Unit(benchmark::kMicrosecond);

// Ten omni views, floor bumps on, people and spurious lights as the simulator draws them: of the
// museum hall at random poses, or of the office (`office`) at poses along its corridors, whose
// rows of lamps near the horizon bloom into long arcs.
struct OmniFrames {
  RobotDescription robot;
  std::vector<Image8> images;
  explicit OmniFrames(bool office) {
    const std::string src = LAMPNAV_SOURCE_DIR;
    robot = read_robot_description(src + "/maps/robots/pioneer.json");
    const auto map = graph::read_map(src + (office ? "/maps/office_floor.geojson"
                                                   : "/maps/domus_museum.geojson"))
                         .map;
    std::vector<const graph::Lamp*> lamps;
    for (const auto& n : map.nodes())
      for (const auto& l : n.lamps) lamps.push_back(&l);
    const sim::OmniRenderer renderer(*robot.find_camera("omni_camera"), {});
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
    for (int k = 0; k < 10; ++k) {
      Pose2 pose;
      if (office) {  // a point on the line between the two ends of an edge, facing along it
        const graph::Edge& e = map.edge_at_index(k % map.edges().size());
        const Eigen::Vector2d a = map.node(e.start).point, b = map.node(e.end).point;
        const Eigen::Vector2d p = a + u(rng) * (b - a);
        pose = Pose2(p.x(), p.y(), std::atan2(b.y() - a.y(), b.x() - a.x()));
      } else {
        pose = Pose2(-2 + 24 * u(rng), -9 + 11 * u(rng), 6.28 * u(rng));
      }
      images.push_back(renderer.render(pose, {bump(rng), bump(rng)}, lamps, rng));
    }
  }
};

// Each set is rendered the first time it is asked for.
const OmniFrames& omni_frames(bool office = false) {
  if (office) {
    static const OmniFrames offices(true);
    return offices;
  }
  static const OmniFrames museum(false);
  return museum;
}

// Argument 1: the office's frames (blooms to split on most of them), 0: the museum's.
void BM_OmniDetector(benchmark::State& state) {
  const OmniFrames& f = omni_frames(state.range(0) == 1);
  vision::OmniLampDetector det(*f.robot.find_camera("omni_camera"));
  std::size_t k = 0;
  double blooms = 0;
  for (auto _ : state) {
    const auto d = det.detect(vision::ImageView::of(f.images[k++ % f.images.size()]));
    blooms += d.split_blooms;
    benchmark::DoNotOptimize(d.blobs.data());
  }
  state.counters["split_blooms"] = blooms / state.iterations();
}
BENCHMARK(BM_OmniDetector)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_PaperOmniPipelineOpenCv(benchmark::State& state) {
  const OmniFrames& f = omni_frames();
  std::size_t k = 0;
  for (auto _ : state) {
    const auto blobs = test::paper_omni_pipeline(f.images[k++ % f.images.size()]);
    benchmark::DoNotOptimize(blobs.data());
  }
}
BENCHMARK(BM_PaperOmniPipelineOpenCv)->Unit(benchmark::kMicrosecond);

// Decoding a 1024 x 1024 omni frame as the node does when it arrives (io::decode_image): PNG as the
// simulator writes, or JPEG at the argument's quality as camera drivers compress.
void BM_DecodeOmniFrame(benchmark::State& state) {
  const OmniFrames& f = omni_frames();
  io::ImageEncoding e;
  e.format = state.range(0) > 0 ? io::ImageEncoding::Format::jpeg : io::ImageEncoding::Format::png;
  if (state.range(0) > 0) e.jpeg_quality = static_cast<int>(state.range(0));
  std::vector<std::string> bytes;
  for (const Image8& image : f.images) bytes.push_back(io::encode_image(image, e));
  std::size_t k = 0;
  for (auto _ : state) {
    const Image8 image = io::decode_image(bytes[k++ % bytes.size()], "omni frame");
    benchmark::DoNotOptimize(image.pixels.data());
  }
}
BENCHMARK(BM_DecodeOmniFrame)->Arg(0)->Arg(90)->Unit(benchmark::kMicrosecond);

// An uncompressed 1024 x 1024 omni frame (sensor_msgs/msg/Image) made grey as the node does when
// it arrives (io::ros2::raw_image_grey: the message read, its pixels converted): mono8, bgr8, a
// webcam's yuyv and a Bayer mosaic (rggb8), each pixel the frame's grey level.
void BM_ReadRawOmniFrame(benchmark::State& state) {
  const OmniFrames& f = omni_frames();
  const char* encoding = std::array{"mono8", "bgr8", "yuyv", "bayer_rggb8"}[state.range(0)];
  const int bytes = test::raw_bytes_per_pixel(encoding);
  std::vector<std::string> messages;
  for (const Image8& image : f.images)
    messages.push_back(test::raw_image_cdr(0, "omni", encoding, image.width, image.height,
                                           image.width * bytes,
                                           test::raw_rows(image.pixels, encoding)));
  std::size_t k = 0;
  for (auto _ : state) {
    const io::ros2::GreyImage g = io::ros2::raw_image_grey(messages[k++ % messages.size()]);
    benchmark::DoNotOptimize(g.image.pixels.data());
  }
  state.SetLabel(encoding);
}
BENCHMARK(BM_ReadRawOmniFrame)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
