#pragma once
// Paper 1's lamp detection in the omnidirectional image (III-D) as published, on OpenCV: binary
// threshold, dilation, Canny edges, contours, and per contour its perimeter and centroid. The
// reference our connected-component detector is measured against (equivalence in the tests,
// speed in bench/vision_bench).

#include <opencv2/imgproc.hpp>
#include <vector>

#include "lampnav/core/image.hpp"

namespace lampnav::test {

struct PaperBlob {
  cv::Point2d centroid;
  int perimeter = 0;  // pixels on the contour ("ratio" in the paper)
  double area = 0;
};

inline std::vector<PaperBlob> paper_omni_pipeline(const Image8& image, int threshold = 128) {
  const cv::Mat grey(image.height, image.width, CV_8UC1,
                     const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat binary, dilated, edges;
  cv::threshold(grey, binary, threshold - 1, 255, cv::THRESH_BINARY);
  cv::dilate(binary, dilated, cv::Mat());  // 3 x 3
  cv::Canny(dilated, edges, 50, 150);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(edges, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<PaperBlob> out;
  for (const auto& c : contours) {
    const cv::Moments m = cv::moments(c);
    PaperBlob b;
    b.perimeter = static_cast<int>(c.size());
    b.area = m.m00;
    if (m.m00 > 0)
      b.centroid = {m.m10 / m.m00, m.m01 / m.m00};
    else {
      cv::Point2d s(0, 0);
      for (const auto& p : c) s += cv::Point2d(p.x, p.y);
      b.centroid = s / static_cast<double>(c.size());
    }
    out.push_back(b);
  }
  return out;
}

}  // namespace lampnav::test
