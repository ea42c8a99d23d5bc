// The blob labeller shared by both lamp detectors (vision/src/blobs.hpp, white-box), against
// OpenCV's connected components (8-connected) on random images of every density, whole and within
// boxes that cut blobs and reach past the image: the same blobs with the same pixel counts,
// bounding boxes and perimeters (pixels with a 4-neighbour dark or outside the box, counted from
// OpenCV's label image).

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <tuple>

#include "blobs.hpp"

namespace lampnav::vision::detail {
namespace {

using Box = std::tuple<int, int, int, int, int, int>;  // pixels, u0, v0, u1, v1, perimeter

std::vector<Box> labelled(const BlobLabeller& lab) {
  std::vector<Box> out;
  for (const Blob& b : lab.blobs()) {
    int pixels = 0;
    for (int k = 0; k < b.run_count; ++k) {
      const Run& r = lab.run(b.first_run + k);
      pixels += r.u1 - r.u0 + 1;
    }
    EXPECT_EQ(pixels, b.pixels);
    out.emplace_back(b.pixels, b.u0, b.v0, b.u1, b.v1, lab.perimeter(b));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Box> opencv(const cv::Mat& grey, std::uint8_t t, const PixelBox& box) {
  cv::Mat mask = cv::Mat::zeros(grey.size(), CV_8UC1);
  const cv::Rect roi(box.u0, box.v0, box.u1 - box.u0 + 1, box.v1 - box.v0 + 1);
  cv::Mat(grey(roi) >= t).copyTo(mask(roi));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  std::vector<int> perimeter(n, 0);
  for (int v = 0; v < labels.rows; ++v)
    for (int u = 0; u < labels.cols; ++u) {
      const int l = labels.at<int>(v, u);
      auto dark = [&](int x, int y) {
        return x < 0 || y < 0 || x >= labels.cols || y >= labels.rows || labels.at<int>(y, x) == 0;
      };
      if (l > 0 && (dark(u - 1, v) || dark(u + 1, v) || dark(u, v - 1) || dark(u, v + 1)))
        ++perimeter[l];
    }
  std::vector<Box> out;
  for (int i = 1; i < n; ++i) {
    const int u0 = stats.at<int>(i, cv::CC_STAT_LEFT), v0 = stats.at<int>(i, cv::CC_STAT_TOP);
    out.emplace_back(stats.at<int>(i, cv::CC_STAT_AREA), u0, v0,
                     u0 + stats.at<int>(i, cv::CC_STAT_WIDTH) - 1,
                     v0 + stats.at<int>(i, cv::CC_STAT_HEIGHT) - 1, perimeter[i]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(BlobLabeller, SameBlobsAsOpenCvsConnectedComponents) {
  std::mt19937 rng(7);
  BlobLabeller lab;  // one labeller for every case: its scratch is reused
  int cases = 0;
  for (const double bright_share : {0.0, 0.001, 0.02, 0.2, 0.5, 0.9, 1.0}) {
    for (const int width : {1, 15, 16, 17, 33, 100}) {
      const int height = 1 + static_cast<int>(rng() % 40);
      cv::Mat grey(height, width, CV_8UC1);
      std::uniform_real_distribution<double> u(0, 1);
      for (int v = 0; v < height; ++v)
        for (int x = 0; x < width; ++x)
          grey.at<std::uint8_t>(v, x) = u(rng) < bright_share
                                            ? static_cast<std::uint8_t>(128 + rng() % 128)
                                            : static_cast<std::uint8_t>(rng() % 128);
      const ImageView view{grey.data, width, height, 1, 1, static_cast<std::size_t>(grey.step)};
      const int du = static_cast<int>(rng() % 5), dv = static_cast<int>(rng() % 5);
      for (const PixelBox& box :
           {PixelBox{0, 0, width - 1, height - 1}, PixelBox{-3, -2, width / 2, height + 4},
            PixelBox{du, dv, width - 1 + 7, height / 2 + dv}}) {
        for (const std::uint8_t t : {std::uint8_t{128}, std::uint8_t{200}, std::uint8_t{255}}) {
          lab.label(view, t, box);
          const PixelBox in{std::max(box.u0, 0), std::max(box.v0, 0), std::min(box.u1, width - 1),
                            std::min(box.v1, height - 1)};
          if (in.u0 > in.u1 || in.v0 > in.v1) {
            EXPECT_TRUE(lab.blobs().empty());
            continue;
          }
          ++cases;
          ASSERT_EQ(labelled(lab), opencv(grey, t, in))
              << width << " x " << height << ", bright share " << bright_share << ", threshold "
              << int(t) << ", box " << box.u0 << " " << box.v0 << " " << box.u1 << " " << box.v1;
        }
      }
    }
  }
  EXPECT_GT(cases, 300);
}

// next_column against its definition, byte by byte: every start, both kinds, rows of 0 to 70
// pixels (so every tail after the 16-pixel blocks), transitions anywhere.
TEST(BlobLabeller, NextColumnIsTheFirstPixelOfTheKindAsked) {
  // Rows of 0 to 200 pixels: scattered bright pixels, or stretches of each kind up to 120 long
  // (a lamp's inside, the dark between lamps), so that the 64-, 16- and 1-pixel steps all stop at
  // every place in a block.
  std::mt19937 rng(3);
  int checked = 0;
  for (int w = 0; w <= 200; ++w) {
    for (int trial = 0; trial < 12; ++trial) {
      std::vector<std::uint8_t> row(static_cast<std::size_t>(w) + 1);
      const auto bright_pixel = [&] { return static_cast<std::uint8_t>(128 + rng() % 128); };
      const auto dark_pixel = [&] { return static_cast<std::uint8_t>(rng() % 128); };
      if (trial % 2 == 0) {
        const int bright_every = 1 + static_cast<int>(rng() % 40);
        for (auto& p : row) p = rng() % bright_every == 0 ? bright_pixel() : dark_pixel();
      } else {
        const int longest = 1 + static_cast<int>(rng() % 120);
        bool bright = rng() % 2 == 0;
        for (std::size_t i = 0; i < row.size();) {
          const std::size_t n = 1 + rng() % longest;
          for (std::size_t k = 0; k < n && i < row.size(); ++k, ++i)
            row[i] = bright ? bright_pixel() : dark_pixel();
          bright = !bright;
        }
      }
      for (int u = 0; u <= w; ++u) {
        for (const bool bright : {true, false}) {
          int expected = u;
          while (expected < w && (row[expected] >= 128) != bright) ++expected;
          ASSERT_EQ(next_column(row.data(), u, w, 128, bright), expected)
              << "w " << w << ", u " << u << (bright ? ", bright" : ", dark");
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 400000);
}

}  // namespace
}  // namespace lampnav::vision::detail
