// Lamp detection on rendered ceiling frames (sim::CeilingRenderer, noise and fringe on), scored
// against the camera model's projection of the true lamps.

#include <algorithm>
#include <cstring>
#include <random>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav/vision/lamp_detector.hpp"
#include "lampnav_test.hpp"
#include "office_world.hpp"

namespace lampnav::vision {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

using World = test::OfficeWorld;

LampShapePrior office_prior() {
  LampShapePrior p;  // 1.2 x 0.3 m lamps at 2.7 m, camera at 0.3 m
  return p;
}

// The truth for one lamp in one frame: where its centre and axis appear, how much of it is seen.
struct LampTruth {
  const graph::Lamp* lamp;
  Vector2d centre_px;    // the image of the lamp's centre
  Vector2d centroid_px;  // the centroid of the lamp's image in undistorted coordinates (they
                         // differ by up to half a pixel when floor bumps tilt the camera)
  double orientation;    // in the normalized plane, mod pi
  double visible;        // fraction of the face inside the image
  bool fully_visible;    // face and fringe inside with a pixel to spare
};

LampTruth truth_of(const sim::CeilingRenderer& r, const PinholeCamera& model, const Pose2& pose,
                   const sim::CameraTilt& tilt, const graph::Lamp& l) {
  LampTruth t{&l, Vector2d::Zero(), Vector2d::Zero(), 0, 0, false};
  const Vector2d axis(std::cos(l.yaw), std::sin(l.yaw)), across(-axis.y(), axis.x());
  auto at = [&](double s, double q) {
    const Vector2d p = l.xyz.head<2>() + s * axis + q * across;
    return r.project(pose, tilt, Vector3d(p.x(), p.y(), l.xyz.z()));
  };
  const auto c = at(0, 0), a = at(0.05, 0), b = at(-0.05, 0);
  if (!c || !a || !b) return t;
  t.centre_px = *c;
  const Vector2d d = model.normalized_of_pixel(*a) - model.normalized_of_pixel(*b);
  t.orientation = std::atan2(d.y(), d.x());
  int in = 0, n = 0;
  // Face samples; each weighted by the image area it covers (a cell's projected parallelogram).
  const int ni = 48, nj = 12;
  const double ds = l.length / ni, dq = l.width / nj;
  auto normalized = [&](double s, double q) {
    const auto p = at(s, q);
    return p ? model.normalized_of_pixel(*p) : Vector2d(1e9, 1e9);
  };
  Vector2d sum = Vector2d::Zero();
  double weight = 0;
  for (int i = 0; i < ni; ++i) {
    for (int j = 0; j < nj; ++j) {
      const double s = (i + 0.5) * ds - l.length / 2, q = (j + 0.5) * dq - l.width / 2;
      const auto p = at(s, q);
      ++n;
      if (p && model.in_image(*p)) ++in;
      const Vector2d x = normalized(s, q);
      const Vector2d ea = normalized(s + ds / 2, q) - normalized(s - ds / 2, q);
      const Vector2d eb = normalized(s, q + dq / 2) - normalized(s, q - dq / 2);
      const double area = std::fabs(ea.x() * eb.y() - ea.y() * eb.x());
      sum += area * x;
      weight += area;
    }
  }
  t.centroid_px = model.pixel_of_normalized(sum / weight);
  t.visible = static_cast<double>(in) / n;
  t.fully_visible = true;
  const double m = 0.04 + 0.01;  // fringe and a bit
  for (double s : {-l.length / 2 - m, l.length / 2 + m}) {
    for (double q : {-l.width / 2 - m, l.width / 2 + m}) {
      const auto p = at(s, q);
      if (!p || p->x() < 1 || p->y() < 1 || p->x() > model.width() - 2 ||
          p->y() > model.height() - 2)
        t.fully_visible = false;
    }
  }
  return t;
}

double angle_mod_pi(double a) {
  a = std::remainder(a, M_PI);
  return std::fabs(a);
}

struct Score {
  int full_lamps = 0, full_found = 0, completed = 0, completable = 0, false_lamps = 0;
  double max_centre_px = 0, max_centre_of_lamp_px = 0, max_orientation_deg = 0,
         max_completed_px = 0;
  double sum_centre_px = 0;
};

// Renders frames from poses along the office corridors and scores every detection.
Score run_frames(const World& w, int frames, double bump_deg, std::uint64_t seed,
                 sim::CeilingRenderOptions render = {}) {
  const sim::CeilingRenderer renderer(w.camera(), render);
  const PinholeCamera model(w.camera());
  LampDetector detector(w.camera(), office_prior());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  std::normal_distribution<double> bump(0, bump_deg * M_PI / 180);
  std::vector<const graph::Node*> corridors;
  for (const auto& n : w.map.nodes())
    if (n.place == graph::Place::corridor && n.axis) corridors.push_back(&n);
  Score s;
  for (int f = 0; f < frames; ++f) {
    const graph::Node& n = *corridors[f % corridors.size()];
    const Vector2d p = n.axis->point_at(uni(rng) * n.axis->length());
    const Vector2d dir = n.axis->direction();
    const double yaw = std::atan2(dir.y(), dir.x()) + (uni(rng) - 0.5) * 0.8 +
                       (f % 5 == 4 ? M_PI / 2 : 0) + (uni(rng) < 0.5 ? M_PI : 0);
    const Pose2 pose(p + Vector2d(dir.y(), -dir.x()) * (uni(rng) - 0.5) * 0.6, yaw);
    const sim::CameraTilt tilt{bump(rng), bump(rng)};
    const auto lamps = w.map.lamps_within(pose.translation(), 5.0);
    const Image8 img = renderer.render(pose, tilt, lamps, rng);
    const LampDetections det = detector.detect(img);
    std::vector<LampTruth> truths;
    for (const auto* l : lamps) truths.push_back(truth_of(renderer, model, pose, tilt, *l));
    for (const auto& t : truths) {
      if (!t.fully_visible) continue;
      ++s.full_lamps;
      for (const auto& d : det.lamps) {
        if (d.view != LampView::full || (d.centre_px - t.centre_px).norm() > 3) continue;
        ++s.full_found;
        const double e = (d.centre_px - t.centroid_px).norm();
        s.max_centre_of_lamp_px =
            std::max(s.max_centre_of_lamp_px, (d.centre_px - t.centre_px).norm());
        s.sum_centre_px += e;
        s.max_centre_px = std::max(s.max_centre_px, e);
        s.max_orientation_deg = std::max(s.max_orientation_deg,
                                         angle_mod_pi(d.orientation - t.orientation) * 180 / M_PI);
      }
    }
    for (const auto& d : det.lamps) {
      // Every detection must be a real lamp: its visible blob lies on a lamp that is in view.
      bool real = false;
      for (const auto& t : truths) {
        if (t.visible <= 0) continue;
        const double tol = d.view == LampView::partial ? 80 : 3;
        if ((d.centre_px - t.centre_px).norm() < tol) real = true;
      }
      if (!real) ++s.false_lamps;
    }
    // Lamps cut by the border with at least 70% in view must come back completed, within 2 px.
    for (const auto& t : truths) {
      if (t.visible > 0.99 || t.visible < 0.7) continue;
      ++s.completable;
      for (const auto& d : det.lamps) {
        if (d.view != LampView::completed || (d.centre_px - t.centre_px).norm() > 10) continue;
        ++s.completed;
        s.max_completed_px = std::max(s.max_completed_px, (d.centre_px - t.centre_px).norm());
      }
    }
  }
  return s;
}

// Without floor bumps the centroid of a lamp's undistorted image is the image of its centre.
TEST(LampDetector, CentroidIsTheLampCentreOnALevelFloor) {
  const World w;
  const Score s = run_frames(w, 150, 0.0, 5);
  ASSERT_GT(s.full_lamps, 80);
  EXPECT_EQ(s.full_found, s.full_lamps);
  EXPECT_LT(s.max_centre_of_lamp_px, 0.5);
  EXPECT_LT(s.max_centre_px, 0.5);
  std::cout << "level floor: " << s.full_lamps << " lamps, max error to the lamp centre "
            << s.max_centre_of_lamp_px << " px\n";
}

TEST(LampDetector, FindsEveryFullyVisibleLampPrecisely) {
  const World w;
  const Score s = run_frames(w, 300, 0.5, 7);
  ASSERT_GT(s.full_lamps, 150);
  EXPECT_EQ(s.full_found, s.full_lamps);
  EXPECT_EQ(s.false_lamps, 0);
  EXPECT_LT(s.max_centre_px, 0.5);
  EXPECT_LT(s.max_orientation_deg, 0.5);
  std::cout << "full lamps " << s.full_lamps << ", mean centre error "
            << s.sum_centre_px / s.full_found << " px, max " << s.max_centre_px
            << " px, max orientation error " << s.max_orientation_deg
            << " deg (to the image of the lamp centre: max " << s.max_centre_of_lamp_px
            << " px, the perspective of the bumps)\n";
}

// Logs store frames as JPEG (io::ImageEncoding). The same rendered frames, lossless and through
// JPEG at several qualities, each lamp paired with itself: at the default quality every lamp is
// found, none invented, none seen otherwise (full, completed, partial), and the centres move by a
// tenth of a pixel on average (0.8 mm on the ceiling).
TEST(LampDetector, JpegFramesGiveTheSameLamps) {
  const World w;
  const sim::CeilingRenderer renderer(w.camera(), {});
  LampDetector detector(w.camera(), office_prior());
  std::mt19937_64 rng(7);
  std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
  std::vector<Image8> frames;
  for (const auto& n : w.map.nodes()) {
    if (n.place != graph::Place::corridor || !n.axis) continue;
    const Vector2d dir = n.axis->direction();
    for (double s = 0.3; s < n.axis->length(); s += 0.35) {
      const Pose2 pose(n.axis->point_at(s), std::atan2(dir.y(), dir.x()));
      frames.push_back(renderer.render(pose, {bump(rng), bump(rng)},
                                       w.map.lamps_within(pose.translation(), 5.0), rng));
    }
  }
  std::vector<LampDetections> lossless;
  std::size_t lamps = 0;
  for (const auto& f : frames) {
    lossless.push_back(detector.detect(f));
    lamps += lossless.back().lamps.size();
  }
  ASSERT_GT(lamps, 350u);
  const int default_quality = io::ImageEncoding{}.jpeg_quality;
  std::cout << frames.size() << " frames, " << lamps << " lamps\n"
            << "quality  frame bytes  lost  new  views changed  centre shift mean / p99 / max px\n";
  for (int q : {95, 75, 50, 30, 10}) {
    io::ImageEncoding jpeg;
    jpeg.jpeg_quality = q;
    std::size_t bytes = 0;
    int lost = 0, added = 0, views = 0;
    std::vector<double> shift;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const std::string data = io::encode_image(frames[k], jpeg);
      bytes += data.size();
      const LampDetections d = detector.detect(io::decode_image(data, "frame"));
      std::vector<char> paired(d.lamps.size(), 0);
      for (const auto& a : lossless[k].lamps) {
        int best = -1;
        for (std::size_t j = 0; j < d.lamps.size(); ++j)
          if (!paired[j] && (d.lamps[j].centre_px - a.centre_px).norm() < 3 &&
              (best < 0 || (d.lamps[j].centre_px - a.centre_px).norm() <
                               (d.lamps[best].centre_px - a.centre_px).norm()))
            best = static_cast<int>(j);
        if (best < 0) {
          ++lost;
          continue;
        }
        paired[best] = 1;
        views += d.lamps[best].view != a.view;
        if (a.view != LampView::partial)
          shift.push_back((d.lamps[best].centre_px - a.centre_px).norm());
      }
      for (char p : paired) added += !p;
    }
    std::sort(shift.begin(), shift.end());
    double mean = 0;
    for (double x : shift) mean += x;
    mean /= static_cast<double>(shift.size());
    const double p99 = shift[shift.size() * 99 / 100], max = shift.back();
    std::cout << "jpeg:" << q << "  " << bytes / frames.size() << "  " << lost << "  " << added
              << "  " << views << "  " << mean << " / " << p99 << " / " << max << "\n";
    if (q < default_quality) continue;
    EXPECT_EQ(lost, 0) << q;
    EXPECT_EQ(added, 0) << q;
    EXPECT_LT(mean, 0.1) << q;
    EXPECT_LT(p99, 0.5) << q;
    EXPECT_EQ(views, 0) << q;
  }
}

TEST(LampDetector, CompletesLampsCutByTheBorder) {
  const World w;
  const Score s = run_frames(w, 300, 0.0, 9);
  ASSERT_GT(s.completable, 30);
  EXPECT_GE(s.completed, s.completable * 9 / 10);
  EXPECT_LT(s.max_completed_px, 2.0);
  std::cout << "completed " << s.completed << " of " << s.completable
            << " lamps more than 70% in view, max centre error " << s.max_completed_px << " px\n";
}

// A tracker reads the image's side columns border_chord_px() / 3 pixels apart (LampTracker): every
// lamp entering there, one or two of its corners in view, must leave at least half of that stretch
// bright in the column (the rest is slack for the blurred ends of the chord, and for a lamp that
// nearly reaches an image corner, where the top or bottom row does not see it yet). Random poses,
// every heading, and the camera at 640x480 too.
void expect_side_columns_cut_lamps_by_the_border_chord(const CameraDescription& camera,
                                                       int frames) {
  const World w;
  const sim::CeilingRenderer renderer(camera, {});
  LampDetector detector(camera, office_prior());
  const double chord = detector.border_chord_px();
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> uni(0, 1);
  std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
  std::vector<const graph::Lamp*> all;
  for (const auto* l : w.map.lamps_within(Vector2d::Zero(), 1e6))
    if (l->shape == graph::LampShape::rectangle) all.push_back(l);
  int cut[3] = {0, 0, 0};  // lamps cut by a side column with 1, 2 and 3 corners in view
  double least = 1e9;      // the fewest column pixels of a lamp entering, over border_chord_px
  for (int f = 0; f < frames; ++f) {
    // The robot within 1.6 m of a lamp, any heading: lamps come in view at every angle.
    const graph::Lamp& near = *all[f % all.size()];
    const double a = uni(rng) * 2 * M_PI, r = 0.6 + 1.0 * uni(rng);
    const Pose2 pose(near.xyz.head<2>() + r * Vector2d(std::cos(a), std::sin(a)),
                     uni(rng) * 2 * M_PI);
    const sim::CameraTilt tilt{bump(rng), bump(rng)};
    const auto lamps = w.map.lamps_within(pose.translation(), 5.0);
    const Image8 img = renderer.render(pose, tilt, lamps, rng);
    for (const LampDetection& d : detector.detect(img).lamps) {
      for (const int u : {0, camera.width - 1}) {
        if (d.bbox[0] > u || d.bbox[2] < u) continue;
        // A lamp cut by the top or bottom row too is seen there: those rows are read whole.
        if (d.bbox[1] == 0 || d.bbox[3] == camera.height - 1) continue;
        int bright = 0;
        for (int v = d.bbox[1]; v <= d.bbox[3]; ++v)
          bright += img.at(u, v) >= detector.options().threshold ? 1 : 0;
        // The lamp under the blob, and how many of its face's corners are in view.
        const graph::Lamp* lamp = nullptr;
        double best = 1e9;
        for (const auto* l : lamps) {
          const auto p = renderer.project(pose, tilt, l->xyz);
          if (p && (*p - d.centre_px).norm() < best) best = (*p - d.centre_px).norm(), lamp = l;
        }
        ASSERT_NE(lamp, nullptr);
        if (lamp->shape != graph::LampShape::rectangle) continue;
        const Vector2d e(std::cos(lamp->yaw), std::sin(lamp->yaw)), n(-e.y(), e.x());
        int in = 0;
        for (double s : {-0.5, 0.5}) {
          for (double q : {-0.5, 0.5}) {
            const Vector2d c = lamp->xyz.head<2>() + s * lamp->length * e + q * lamp->width * n;
            const auto p = renderer.project(pose, tilt, Vector3d(c.x(), c.y(), lamp->xyz.z()));
            in += p && p->x() >= 0 && p->y() >= 0 && p->x() <= camera.width - 1 &&
                          p->y() <= camera.height - 1
                      ? 1
                      : 0;
          }
        }
        if (in < 1 || in > 3) continue;
        ++cut[in - 1];
        // Three corners in view: the lamp came in across two sides first (a short chord now).
        if (in == 3) continue;
        least = std::min(least, bright / chord);
        EXPECT_GE(bright, chord / 2)
            << "frame " << f << ": " << lamp->id.value << " with " << in
            << " corners in view covers " << bright << " px of column " << u;
      }
    }
  }
  std::cout << camera.width << "x" << camera.height << ": border chord " << chord
            << " px; lamps cut by a side column with 1, 2, 3 corners in view: " << cut[0] << ", "
            << cut[1] << ", " << cut[2] << "; the fewest column pixels of one entering " << least
            << " chords\n";
  EXPECT_GT(cut[1], 100);
  // The bound is tight enough to be worth reading columns sparsely.
  EXPECT_GT(chord, camera.width / 20.0);
}

TEST(LampDetector, LampsEnteringByASideCoverTheBorderChordOfItsColumn) {
  const World w;
  expect_side_columns_cut_lamps_by_the_border_chord(w.camera(), 1000);
  expect_side_columns_cut_lamps_by_the_border_chord(w.camera_640(), 600);
}

TEST(LampDetector, NoLampInNoiseOrOnBrightFringes) {
  const World w;
  sim::CeilingRenderOptions bright;
  bright.exposure = 2.0;  // the grid's fringe reaches 120: right under the threshold
  bright.noise_sigma = 8;
  const Score s = run_frames(w, 60, 0.5, 21, bright);
  EXPECT_EQ(s.false_lamps, 0);
  // Pure noise, and scattered specks, find nothing.
  LampDetector detector(w.camera(), office_prior());
  std::mt19937 rng(4);
  Image8 specks(352, 288, 10);
  std::uniform_int_distribution<int> u(0, 351), v(0, 287);
  for (int i = 0; i < 4000; ++i) specks.at(u(rng), v(rng)) = 255;
  EXPECT_TRUE(detector.detect(specks).lamps.empty());
  EXPECT_GT(detector.detect(specks).stats.too_small, 1000);
}

TEST(LampDetector, SaturatedAndBlackFramesYieldNoLamps) {
  const World w;
  LampDetector detector(w.camera(), office_prior());
  const auto white = detector.detect(Image8(352, 288, 255));
  EXPECT_TRUE(white.lamps.empty());
  EXPECT_EQ(white.stats.too_large, 1);
  EXPECT_TRUE(detector.detect(Image8(352, 288, 0)).lamps.empty());
}

TEST(LampDetector, RefusesFramesThatAreNotTheCamerasImages) {
  const World w;
  LampDetector detector(w.camera(), office_prior());
  auto message = [&](const ImageView& v) {
    try {
      detector.detect(v);
    } catch (const InputError& e) {
      return e.message();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(ImageView::of(Image8())), "the image is empty");
  EXPECT_EQ(message(ImageView::of(Image8(640, 480))),
            "the image is 640x480 but the camera is 352x288");
  std::vector<std::uint8_t> buf(352 * 288 * 2);
  EXPECT_THAT(message({buf.data(), 352, 288, 2, 1, 0}), testing::HasSubstr("2 channels"));
  EXPECT_THAT(message({buf.data(), 352, 288, 1, 4, 0}), testing::HasSubstr("32-bit samples"));
  EXPECT_THAT(message({buf.data(), 352, 288, 1, 1, 100}), testing::HasSubstr("row stride"));
}

// Colour (BGR) and 16-bit versions of a frame give the same lamps as the grey frame.
TEST(LampDetector, ColourAnd16BitFramesAreConverted) {
  const World w;
  const sim::CeilingRenderer renderer(w.camera(), {});
  std::mt19937_64 rng(3);
  const Pose2 pose(w.map.find_node("C1")->axis->point_at(4.0), 0.3);
  const Image8 grey = renderer.render(pose, {}, w.map.lamps_within(pose.translation(), 5), rng);
  std::vector<std::uint8_t> bgr(grey.pixels.size() * 3);
  std::vector<std::uint16_t> deep(grey.pixels.size());
  for (std::size_t i = 0; i < grey.pixels.size(); ++i) {
    bgr[3 * i] = bgr[3 * i + 1] = bgr[3 * i + 2] = grey.pixels[i];
    deep[i] = static_cast<std::uint16_t>(grey.pixels[i] * 257);
  }
  LampDetector detector(w.camera(), office_prior());
  const auto a = detector.detect(grey);
  const auto b = detector.detect(ImageView{bgr.data(), 352, 288, 3, 1, 0});
  const auto c = detector.detect(
      ImageView{reinterpret_cast<const std::uint8_t*>(deep.data()), 352, 288, 1, 2, 0});
  ASSERT_FALSE(a.lamps.empty());
  ASSERT_EQ(a.lamps.size(), b.lamps.size());
  ASSERT_EQ(a.lamps.size(), c.lamps.size());
  for (std::size_t i = 0; i < a.lamps.size(); ++i) {
    EXPECT_LT((a.lamps[i].centre_px - b.lamps[i].centre_px).norm(), 1e-9);
    EXPECT_LT((a.lamps[i].centre_px - c.lamps[i].centre_px).norm(), 1e-9);
  }
}

TEST(LampDetector, OptionsAndPriorAreValidated) {
  const World w;
  LampDetectorOptions o;
  o.threshold = 0;
  try {
    LampDetector d(w.camera(), office_prior(), o);
    FAIL() << "accepted threshold 0";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().field, "threshold");
  }
  LampShapePrior p;
  p.width = 2.0;
  EXPECT_THROW(LampDetector(w.camera(), p), InputError);
  CameraDescription fisheye = *w.robot.find_camera("omni_camera");
  EXPECT_THROW(LampDetector(fisheye, office_prior()), Error);
}

}  // namespace
}  // namespace lampnav::vision
