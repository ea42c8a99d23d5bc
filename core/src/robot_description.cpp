#include "lampnav/core/robot_description.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <set>

#include "lampnav/internal/json_util.hpp"

namespace lampnav {

using json::Cursor;
using json::Json;

Eigen::Matrix3d Mount::rotation() const {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

const CameraDescription* RobotDescription::find_camera(const std::string& camera_name) const {
  for (const auto& c : cameras) {
    if (c.name == camera_name) return &c;
  }
  return nullptr;
}

namespace {

Eigen::Vector3d read_vec3(const Cursor& c) {
  c.array_size(3, 3);
  return {c[0].number(), c[1].number(), c[2].number()};
}

Mount read_mount(const Cursor& c) {
  c.only_keys({"xyz", "rpy"});
  Mount m;
  m.xyz = read_vec3(c.at("xyz"));
  m.rpy = read_vec3(c.at("rpy"));
  return m;
}

int read_size(const Cursor& c) {
  const auto v = c.integer();
  if (v <= 0 || v > 100000) c.fail("must be a pixel count from 1 to 100000");
  return static_cast<int>(v);
}

// A fisheye's optional field of view (else its model's default).
void read_fov(const Cursor& c, FisheyeParameters& f) {
  if (auto fov = c.find("fov_deg")) {
    f.fov_deg = fov->positive();
    if (f.fov_deg >= 360.0) fov->fail("must be below 360 degrees");
  }
}

CameraDescription read_camera(const Cursor& c) {
  c.expect_object();
  CameraDescription cam;
  cam.name = c.at("name").string();
  const std::string model = c.at("model").string();
  cam.width = read_size(c.at("width"));
  cam.height = read_size(c.at("height"));
  cam.mount = read_mount(c.at("mount"));
  if (model == "pinhole") {
    c.only_keys(
        {"name", "model", "width", "height", "fx", "fy", "cx", "cy", "distortion", "mount"});
    cam.model = CameraModelKind::pinhole;
    auto& p = cam.pinhole;
    p.fx = c.at("fx").positive();
    p.fy = c.at("fy").positive();
    p.cx = c.at("cx").number();
    p.cy = c.at("cy").number();
    if (auto d = c.find("distortion")) {
      d->array_size(5, 5);
      for (std::size_t i = 0; i < 5; ++i) p.distortion[i] = (*d)[i].number();
    }
  } else if (model == "pajdla_bakstein") {
    c.only_keys({"name", "model", "width", "height", "u0", "v0", "a", "b", "c", "d", "beta",
                 "fov_deg", "mount"});
    cam.model = CameraModelKind::pajdla_bakstein;
    auto& f = cam.fisheye;
    f.u0 = c.at("u0").number();
    f.v0 = c.at("v0").number();
    f.a = c.at("a").number();
    f.b = c.at("b").number();
    f.c = c.at("c").number();
    f.d = c.at("d").number();
    if (f.b == 0.0) c.at("b").fail("must not be zero (r = a tan(theta / b) + ...)");
    if (f.d == 0.0) c.at("d").fail("must not be zero (r = ... + c sin(theta / d))");
    if (auto beta = c.find("beta")) f.beta = beta->positive();
    read_fov(c, f);
  } else if (model == "kannala_brandt") {
    c.only_keys(
        {"name", "model", "width", "height", "fx", "fy", "cx", "cy", "k", "fov_deg", "mount"});
    cam.model = CameraModelKind::kannala_brandt;
    auto& f = cam.fisheye;
    f.f = c.at("fx").positive();
    f.beta = c.at("fy").positive() / f.f;
    f.u0 = c.at("cx").number();
    f.v0 = c.at("cy").number();
    const Cursor k = c.at("k");
    k.array_size(4, 4);
    for (std::size_t i = 0; i < 4; ++i) f.k[i] = k[i].number();
    f.fov_deg = 180.0;
    read_fov(c, f);
  } else {
    c.at("model").fail("unknown camera model '" + model +
                       "' (expected pinhole, pajdla_bakstein or kannala_brandt)");
  }
  return cam;
}

}  // namespace

const char* to_string(CameraModelKind k) {
  switch (k) {
    case CameraModelKind::pinhole:
      return "pinhole";
    case CameraModelKind::pajdla_bakstein:
      return "pajdla_bakstein";
    case CameraModelKind::kannala_brandt:
      return "kannala_brandt";
  }
  return "?";
}

RobotDescription parse_robot_description(const std::string& text, const std::string& source) {
  const Json doc = json::parse(text, source);
  const Cursor root(doc, {source, "", ""});
  root.only_keys({"name", "wheels", "cameras"});
  RobotDescription robot;
  robot.name = root.at("name").string();
  const Cursor wheels = root.at("wheels");
  wheels.only_keys({"semi_axis"});
  robot.semi_axis = wheels.at("semi_axis").positive();
  if (auto cams = root.find("cameras")) {
    const std::size_t n = cams->array_size();
    std::set<std::string> names;
    for (std::size_t i = 0; i < n; ++i) {
      Cursor c = (*cams)[i];
      ErrorContext w = c.where();
      w.place = "camera " + std::to_string(i);
      if (c.value().is_object() && c.value().contains("name") && c.value()["name"].is_string()) {
        w.place += " (" + c.value()["name"].get<std::string>() + ")";
      }
      w.field.clear();
      Cursor placed(c.value(), w);
      CameraDescription cam = read_camera(placed);
      if (!names.insert(cam.name).second) placed.at("name").fail("duplicate camera name");
      robot.cameras.push_back(std::move(cam));
    }
  }
  return robot;
}

RobotDescription read_robot_description(const std::string& path) {
  return parse_robot_description(json::read_file(path), path);
}

std::string to_robot_json(const RobotDescription& robot) {
  Json j;
  j["name"] = robot.name;
  j["wheels"] = {{"semi_axis", robot.semi_axis}};
  j["cameras"] = Json::array();
  for (const auto& c : robot.cameras) {
    Json cj;
    cj["name"] = c.name;
    cj["width"] = c.width;
    cj["height"] = c.height;
    if (c.model == CameraModelKind::pinhole) {
      cj["model"] = to_string(c.model);
      cj["fx"] = c.pinhole.fx;
      cj["fy"] = c.pinhole.fy;
      cj["cx"] = c.pinhole.cx;
      cj["cy"] = c.pinhole.cy;
      cj["distortion"] = c.pinhole.distortion;
    } else if (c.model == CameraModelKind::kannala_brandt) {
      const auto& f = c.fisheye;
      cj["model"] = to_string(c.model);
      cj["fx"] = f.f;
      cj["fy"] = f.f * f.beta;
      cj["cx"] = f.u0;
      cj["cy"] = f.v0;
      cj["k"] = f.k;
      cj["fov_deg"] = f.fov_deg;
    } else {
      const auto& f = c.fisheye;
      cj["model"] = to_string(c.model);
      cj["u0"] = f.u0;
      cj["v0"] = f.v0;
      cj["a"] = f.a;
      cj["b"] = f.b;
      cj["c"] = f.c;
      cj["d"] = f.d;
      cj["beta"] = f.beta;
      cj["fov_deg"] = f.fov_deg;
    }
    cj["mount"] = {{"xyz", {c.mount.xyz.x(), c.mount.xyz.y(), c.mount.xyz.z()}},
                   {"rpy", {c.mount.rpy.x(), c.mount.rpy.y(), c.mount.rpy.z()}}};
    j["cameras"].push_back(std::move(cj));
  }
  return j.dump(2) + "\n";
}

}  // namespace lampnav
