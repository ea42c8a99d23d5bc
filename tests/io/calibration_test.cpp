// Calibrations from the usual tools become robot.json cameras that project as the tools' own
// models do: OpenCV's cv::projectPoints (radial-tangential) and cv::fisheye::projectPoints
// (Kannala-Brandt), compared over the whole image to 0.01 px. OpenCV's files are written by
// OpenCV's own cv::FileStorage; ROS camera_info and Kalibr camchain files as those tools write
// them.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "lampnav/core/error.hpp"
#include "lampnav/io/calibration.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav_test.hpp"

namespace lampnav::io {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using ::testing::HasSubstr;

std::string write(const std::string& name, const std::string& text) {
  const std::string path = test::temp_path(name);
  std::ofstream(path) << text;
  return path;
}

// The worst distance (px) between our projection of the imported camera and OpenCV's, over rays
// through every 4th pixel of the image.
double worst_against_opencv(const CameraDescription& c, const cv::Matx33d& K,
                            const std::vector<double>& D, bool fisheye) {
  std::vector<cv::Point3d> points;
  std::vector<Vector2d> ours;
  if (fisheye) {
    const vision::FisheyeCamera cam(c);
    for (int v = 0; v < c.height; v += 4)
      for (int u = 0; u < c.width; u += 4) {
        const auto ray = cam.unproject(Vector2d(u, v));
        if (!ray || ray->z() < 0.02) continue;
        points.emplace_back(ray->x(), ray->y(), ray->z());
        ours.push_back(*cam.project(*ray));
      }
  } else {
    const vision::PinholeCamera cam(c);
    for (int v = 0; v < c.height; v += 4)
      for (int u = 0; u < c.width; u += 4) {
        const Vector3d ray = cam.unproject(Vector2d(u, v));
        const auto px = cam.project(ray);
        if (!px) continue;
        points.emplace_back(ray.x(), ray.y(), ray.z());
        ours.push_back(*px);
      }
  }
  EXPECT_GT(points.size(), std::size_t(c.width * c.height / 16 / 2));
  std::vector<cv::Point2d> theirs;
  if (fisheye)
    cv::fisheye::projectPoints(points, theirs, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                               cv::Vec4d(D[0], D[1], D[2], D[3]));
  else
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, theirs);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, (ours[i] - Vector2d(theirs[i].x, theirs[i].y)).norm());
  return worst;
}

TEST(Calibration, RosCameraInfoPlumbBobAndEquidistant) {
  const std::string webcam = write("webcam.yaml", R"(image_width: 640
image_height: 480
camera_name: ceiling_webcam
camera_matrix:
  rows: 3
  cols: 3
  data: [612.3, 0, 318.2, 0, 610.8, 241.7, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.112, 0.071, 0.0012, -0.0007, -0.013]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [612.3, 0, 318.2, 0, 0, 610.8, 241.7, 0, 0, 0, 1, 0]
)");
  const auto w = read_calibration(webcam);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].format, "ROS camera_info");
  EXPECT_EQ(w[0].label, "ceiling_webcam");
  EXPECT_EQ(w[0].camera.model, CameraModelKind::pinhole);
  const double worst_pinhole =
      worst_against_opencv(w[0].camera, cv::Matx33d(612.3, 0, 318.2, 0, 610.8, 241.7, 0, 0, 1),
                           {-0.112, 0.071, 0.0012, -0.0007, -0.013}, false);
  const std::string fish = write("fish.yaml", R"(image_width: 1280
image_height: 1024
camera_name: omni
camera_matrix: {rows: 3, cols: 3, data: [402.1, 0, 641.3, 0, 401.7, 509.2, 0, 0, 1]}
distortion_model: equidistant
distortion_coefficients: {rows: 1, cols: 4, data: [0.034, -0.0041, 0.00062, -0.00009]}
)");
  const auto f = read_calibration(fish);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].camera.model, CameraModelKind::kannala_brandt);
  const double worst_fisheye =
      worst_against_opencv(f[0].camera, cv::Matx33d(402.1, 0, 641.3, 0, 401.7, 509.2, 0, 0, 1),
                           {0.034, -0.0041, 0.00062, -0.00009}, true);
  std::cout << "against OpenCV: pinhole " << worst_pinhole << " px, fisheye " << worst_fisheye
            << " px\n";
  EXPECT_LT(worst_pinhole, 0.01);
  EXPECT_LT(worst_fisheye, 0.01);
  std::filesystem::remove(webcam);
  std::filesystem::remove(fish);
}

// A driver's CameraInfo (a bag's, a live camera's) is read as its YAML is; one published
// uncalibrated (K all zero) describes nothing; a model lampnav does not read is refused naming
// the topic, the frame and the field. projection_difference_px tells a description from itself
// (below 1e-6 px: the pinhole's undistortion is iterative), from the same camera 0.5 % longer in
// focal length (more than 1 px at the edges), and from another size (infinity).
TEST(Calibration, CameraInfoMessagesAndHowFarApartTwoDescriptionsAre) {
  CameraInfo info;
  info.frame_id = "ceiling_optical";
  info.width = 640;
  info.height = 480;
  info.distortion_model = "plumb_bob";
  info.d = {-0.112, 0.071, 0.0012, -0.0007, -0.013};
  info.k = {612.3, 0, 318.2, 0, 610.8, 241.7, 0, 0, 1};
  const auto from_message = camera_from_info(info, "/ceiling/camera_info");
  ASSERT_TRUE(from_message);
  EXPECT_EQ(from_message->model, CameraModelKind::pinhole);
  EXPECT_EQ(from_message->pinhole.fx, 612.3);
  EXPECT_EQ(from_message->pinhole.cy, 241.7);
  EXPECT_EQ(from_message->pinhole.distortion[4], -0.013);
  EXPECT_LT(vision::projection_difference_px(*from_message, *from_message), 1e-6);

  CameraDescription longer = *from_message;
  longer.pinhole.fx *= 1.005;
  longer.pinhole.fy *= 1.005;
  const double apart = vision::projection_difference_px(*from_message, longer);
  std::cout << "0.5 % longer focal length: " << apart << " px apart\n";
  EXPECT_GT(apart, 1.0);
  EXPECT_LT(apart, 3.0);
  CameraDescription smaller = *from_message;
  smaller.width = 320;
  EXPECT_TRUE(std::isinf(vision::projection_difference_px(*from_message, smaller)));

  CameraInfo fish = info;
  fish.distortion_model = "equidistant";
  fish.d = {0.034, -0.0041, 0.00062, -0.00009};
  const auto kb = camera_from_info(fish, "/omni/camera_info");
  ASSERT_TRUE(kb);
  EXPECT_EQ(kb->model, CameraModelKind::kannala_brandt);
  EXPECT_LT(vision::projection_difference_px(*kb, *kb), 1e-6);

  CameraInfo uncalibrated = info;
  uncalibrated.k = {};
  EXPECT_FALSE(camera_from_info(uncalibrated, "/ceiling/camera_info"));
  CameraInfo unknown = info;
  unknown.distortion_model = "double_sphere";
  try {
    camera_from_info(unknown, "/ceiling/camera_info");
    ADD_FAILURE() << "an unknown model was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/ceiling/camera_info"));
    EXPECT_THAT(e.what(), HasSubstr("ceiling_optical"));
    EXPECT_THAT(e.what(), HasSubstr("double_sphere"));
  }
}

TEST(Calibration, KalibrCamchainWithBothCameras) {
  const std::string path = write("camchain.yaml", R"(cam0:
  cam_overlaps: []
  camera_model: pinhole
  distortion_coeffs: [-0.29, 0.08, 0.00019, 1.9e-05]
  distortion_model: radtan
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  resolution: [752, 480]
  rostopic: /ceiling/image_raw
cam1:
  T_cn_cnm1:
  - [0.99, 0.01, 0.0, -0.11]
  - [-0.01, 0.99, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.0134, 0.0212, -0.0159, 0.0036]
  distortion_model: equidistant
  intrinsics: [190.97, 190.97, 254.93, 256.89]
  resolution: [512, 512]
  rostopic: /omni/image_raw
)");
  const auto cams = read_calibration(path);
  std::filesystem::remove(path);
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[0].label, "cam0 (/ceiling/image_raw)");
  EXPECT_EQ(cams[0].camera.model, CameraModelKind::pinhole);
  EXPECT_EQ(cams[0].camera.width, 752);
  EXPECT_EQ(cams[1].camera.model, CameraModelKind::kannala_brandt);
  EXPECT_LT(worst_against_opencv(cams[0].camera,
                                 cv::Matx33d(458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1),
                                 {-0.29, 0.08, 0.00019, 1.9e-05, 0}, false),
            0.01);
  EXPECT_LT(worst_against_opencv(cams[1].camera,
                                 cv::Matx33d(190.97, 0, 254.93, 0, 190.97, 256.89, 0, 0, 1),
                                 {-0.0134, 0.0212, -0.0159, 0.0036}, true),
            0.01);
}

// Files written by OpenCV's own cv::FileStorage, XML and YAML, as its calibration sample does.
TEST(Calibration, OpenCvFilesWrittenByOpenCv) {
  for (const char* ext : {".xml", ".yaml"}) {
    for (const bool fisheye : {false, true}) {
      const std::string path =
          test::temp_path(std::string("opencv") + (fisheye ? "_fish" : "") + ext);
      const cv::Matx33d K(500.5, 0, 319.1, 0, 501.2, 238.9, 0, 0, 1);
      const std::vector<double> D = fisheye
                                        ? std::vector<double>{0.05, -0.01, 0.002, -0.0002}
                                        : std::vector<double>{-0.2, 0.05, 0.001, 0.0005, -0.004};
      {
        cv::FileStorage fs(path, cv::FileStorage::WRITE);
        fs << "image_width" << 640 << "image_height" << 480;
        fs << "camera_matrix" << cv::Mat(K);
        fs << "distortion_coefficients" << cv::Mat(D);
        if (fisheye) fs << "fisheye_model" << 1;
        fs << "avg_reprojection_error" << 0.21;
      }
      const auto cams = read_calibration(path);
      std::filesystem::remove(path);
      ASSERT_EQ(cams.size(), 1u) << ext;
      EXPECT_EQ(cams[0].format, "OpenCV");
      EXPECT_EQ(cams[0].camera.model,
                fisheye ? CameraModelKind::kannala_brandt : CameraModelKind::pinhole);
      EXPECT_LT(worst_against_opencv(cams[0].camera, K, D, fisheye), 0.01) << ext;
    }
  }
}

TEST(Calibration, WhatCannotBeReadIsRefusedNamingFileAndField) {
  auto refused = [](const std::string& name, const std::string& text, const std::string& field,
                    const std::string& what) {
    const std::string path = write(name, text);
    try {
      read_calibration(path);
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where().file, path) << name;
      EXPECT_EQ(e.where().field, field) << name << ": " << e.what();
      EXPECT_THAT(e.what(), HasSubstr(what)) << name;
    }
    std::filesystem::remove(path);
  };
  const std::string matrix =
      "camera_matrix: {rows: 3, cols: 3, data: [300, 0, 160, 0, 300, 120, 0, 0, 1]}\n";
  refused(
      "model.yaml",
      "image_width: 320\nimage_height: 240\n" + matrix +
          "distortion_model: unified\ndistortion_coefficients: {rows: 1, cols: 1, data: [0.9]}\n",
      "distortion_coefficients", "distortion model 'unified' is not read");
  refused("count.yaml",
          "image_width: 320\nimage_height: 240\n" + matrix +
              "distortion_model: equidistant\ndistortion_coefficients: {rows: 1, cols: 3, data: "
              "[0.1, 0.2, 0.3]}\n",
          "distortion_coefficients", "needs 4 coefficients");
  refused("skew.yaml",
          "image_width: 320\nimage_height: 240\ncamera_matrix: {rows: 3, cols: 3, data: [300, 2, "
          "160, 0, 300, 120, 0, 0, 1]}\ndistortion_model: plumb_bob\ndistortion_coefficients: "
          "{rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\n",
          "camera_matrix", "skew");
  refused(
      "rows.yaml",
      "image_width: 320\nimage_height: 240\ncamera_matrix: {rows: 3, cols: 3, data: [300, 0, "
      "160, 0, 300, 120]}\ndistortion_model: plumb_bob\ndistortion_coefficients: [0, 0, 0, 0]\n",
      "camera_matrix", "data holds 6 numbers");
  // Found by the fuzzer: a count beyond any int was cast to one.
  refused("huge_rows.yaml",
          "image_width: 320\nimage_height: 240\ncamera_matrix: {rows: 4e84, cols: 3, data: [300, "
          "0, 160]}\ndistortion_model: plumb_bob\ndistortion_coefficients: [0, 0, 0, 0]\n",
          "camera_matrix.rows", "whole count");
  refused("width.yaml",
          "image_width: -3\nimage_height: 240\n" + matrix +
              "distortion_model: plumb_bob\ndistortion_coefficients: [0, 0, 0, 0]\n",
          "image_width", "pixel count");
  refused(
      "kalibr.yaml",
      "cam0:\n  camera_model: omni\n  intrinsics: [0.8, 300, 300, 160, 120]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n  resolution: [320, 240]\n",
      "camera_model", "'omni' is not read");
  refused(
      "kalibr2.yaml",
      "cam0:\n  camera_model: pinhole\n  intrinsics: [300, 300, 160]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n  resolution: [320, 240]\n",
      "intrinsics", "[fu, fv, pu, pv]");
  refused("other.yaml", "name: something\nsize: 3\n", "", "not a calibration lampnav reads");
  refused("garbage.yaml", "{{{{ not yaml", "", "not a YAML or XML calibration file");
  // Found by the fuzzer: an attribute without its opening quote made OpenCV's XML parser read
  // address 0; the XML is now read by tinyxml2, and the line is named.
  const std::string xml_matrix =
      "<rows>3</rows><cols>3</cols><dt>d</dt><data>300. 0. 160. 0. 300. 120. 0. 0. "
      "1.</data></camera_matrix>\n";
  refused("unquoted.xml",
          "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>320</image_width>\n"
          "<camera_matrix type_id=ncv-matrix\">" +
              xml_matrix + "</opencv_storage>\n",
          "", "line 4");
  refused("twice.yaml", "image_width: 320\nimage_height: 240\nimage_width: 640\n", "image_width",
          "line 3");
  refused("twice.xml",
          "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>320</image_width>\n"
          "<image_width>640</image_width>\n</opencv_storage>\n",
          "image_width", "line 4");
  refused("root.xml", "<?xml version=\"1.0\"?>\n<calibration><a>1</a></calibration>\n", "",
          "<opencv_storage>");
  refused("xml_rows.xml",
          "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>320</image_width>\n"
          "<image_height>240</image_height>\n<camera_matrix type_id=\"opencv-matrix\">"
          "<rows>3</rows><cols>3</cols><dt>d</dt><data>300. 0. 160. 0. 300. 120.</data>"
          "</camera_matrix>\n<distortion_coefficients type_id=\"opencv-matrix\"><rows>4</rows>"
          "<cols>1</cols><dt>d</dt><data>0 0 0 0</data></distortion_coefficients>\n"
          "</opencv_storage>\n",
          "camera_matrix", "data holds 6 numbers");
}

}  // namespace
}  // namespace lampnav::io
