#include "lampnav/io/calibration.hpp"

#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <sstream>

#include "lampnav/core/error.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/io/mission_log.hpp"

namespace lampnav::io {

namespace {

// A parsed file as a plain tree, whichever parser read it: yaml-cpp for YAML (ROS, Kalibr and
// OpenCV's "%YAML:1.0" files with their !!opencv-matrix), tinyxml2 for OpenCV's XML. OpenCV's own
// cv::FileStorage is not used on files from outside: fuzzing found a 791-byte YAML file on which
// it never returns and a 408-byte XML file on which it reads address 0 (OpenCV 4.6).
struct Node {
  enum Kind { none, scalar, list, map } kind = none;
  std::string text;  // a scalar as written
  std::vector<Node> items;
  std::map<std::string, Node> keys;
  const Node& operator[](const std::string& key) const {
    static const Node missing;
    const auto it = keys.find(key);
    return it == keys.end() ? missing : it->second;
  }
  bool empty() const { return kind == none; }
};

// A key given twice in one map is refused, not the last taken.
Node from_yaml(const YAML::Node& y, const std::string& path) {
  Node n;
  if (y.IsScalar()) {
    n.kind = Node::scalar;
    n.text = y.Scalar();
  } else if (y.IsSequence()) {
    n.kind = Node::list;
    for (const auto& item : y) n.items.push_back(from_yaml(item, path));
  } else if (y.IsMap()) {
    n.kind = Node::map;
    for (const auto& kv : y) {
      const std::string key = kv.first.as<std::string>();
      if (!n.keys.emplace(key, from_yaml(kv.second, path)).second)
        throw InputError({path, "line " + std::to_string(kv.first.Mark().line + 1), key},
                         "given twice");
    }
  }
  return n;
}

// OpenCV's XML (cv::FileStorage's format): an element holding elements is a map of them by name,
// or a list when they are all named "_"; an element holding text is a value, or a list of values
// when the text holds several separated by spaces (a matrix's data); a quoted text is one value.
// A name given twice in one element is refused (OpenCV never writes one).
Node from_xml(const tinyxml2::XMLElement& e, const std::string& path) {
  Node n;
  const tinyxml2::XMLElement* child = e.FirstChildElement();
  if (child) {
    bool all_unnamed = true;
    for (auto* c = child; c; c = c->NextSiblingElement())
      all_unnamed = all_unnamed && std::string(c->Name()) == "_";
    n.kind = all_unnamed ? Node::list : Node::map;
    for (auto* c = child; c; c = c->NextSiblingElement()) {
      if (all_unnamed)
        n.items.push_back(from_xml(*c, path));
      else if (!n.keys.emplace(c->Name(), from_xml(*c, path)).second)
        throw InputError({path, "line " + std::to_string(c->GetLineNum()), c->Name()},
                         "given twice in <" + std::string(e.Name()) + ">");
    }
    return n;
  }
  const std::string text = e.GetText() ? e.GetText() : "";
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return n;  // an empty element: nothing
  const auto last = text.find_last_not_of(" \t\r\n");
  if (text[first] == '"' && last > first && text[last] == '"') {
    n.kind = Node::scalar;
    n.text = text.substr(first + 1, last - first - 1);
    return n;
  }
  std::istringstream words(text);
  for (std::string word; words >> word;) n.items.push_back(Node{Node::scalar, word, {}, {}});
  if (n.items.size() == 1) return n.items.front();
  n.kind = Node::list;
  return n;
}

// One place in one file, for errors.
struct Where {
  std::string file, place;
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError({file, place, field}, what);
  }
};

const char* kind_name(const Node& n) {
  switch (n.kind) {
    case Node::none:
      return "nothing";
    case Node::scalar:
      return "a value";
    case Node::list:
      return "a list";
    case Node::map:
      return "a map";
  }
  return "?";
}

const Node& need(const Node& parent, const std::string& key, const Where& w) {
  const Node& n = parent[key];
  if (n.empty()) w.fail(key, "missing");
  return n;
}

double number(const Node& n, const std::string& field, const Where& w) {
  if (n.kind != Node::scalar) w.fail(field, std::string("must be a number, is ") + kind_name(n));
  char* end = nullptr;
  const double v = std::strtod(n.text.c_str(), &end);
  if (n.text.empty() || *end != 0) w.fail(field, "'" + n.text + "' is not a number");
  if (!std::isfinite(v)) w.fail(field, "must be finite");
  return v;
}

std::string text(const Node& n, const std::string& field, const Where& w) {
  if (n.kind != Node::scalar) w.fail(field, std::string("must be text, is ") + kind_name(n));
  return n.text;
}

int pixels(const Node& n, const std::string& field, const Where& w) {
  const double v = number(n, field, w);
  if (v != std::floor(v) || v < 1 || v > 100000)
    w.fail(field, "must be a pixel count, 1 to 100000");
  return static_cast<int>(v);
}

// A list of numbers, or a matrix: ROS's {rows, cols, data}, OpenCV's !!opencv-matrix (the same
// keys, and dt).
std::vector<double> numbers(const Node& n, const std::string& field, const Where& w) {
  std::vector<double> out;
  if (n.kind == Node::map) {
    const Node& data = need(n, "data", w);
    if (data.kind != Node::list) w.fail(field + ".data", "must be a list of numbers");
    for (const auto& x : data.items) out.push_back(number(x, field + ".data", w));
    if (!n["rows"].empty() && !n["cols"].empty()) {
      const double rows = number(n["rows"], field + ".rows", w),
                   cols = number(n["cols"], field + ".cols", w);
      for (const auto& [v, part] : {std::pair{rows, ".rows"}, std::pair{cols, ".cols"}})
        if (v != std::floor(v) || v < 0 || v > 1e6)
          w.fail(field + part, "must be a whole count, 0 to 1000000");
      if (rows * cols != double(out.size()))
        w.fail(field, "rows x cols is " + std::to_string(static_cast<long long>(rows * cols)) +
                          " but data holds " + std::to_string(out.size()) + " numbers");
    }
    return out;
  }
  if (n.kind != Node::list)
    w.fail(field, std::string("must be a list of numbers, is ") + kind_name(n));
  for (const auto& x : n.items) out.push_back(number(x, field, w));
  return out;
}

// fx, fy, cx, cy from a 3 x 3 camera matrix (no skew).
void from_matrix(const std::vector<double>& K, const std::string& field, const Where& w, double& fx,
                 double& fy, double& cx, double& cy) {
  if (K.size() != 9)
    w.fail(field, "must be a 3 x 3 matrix (9 numbers), has " + std::to_string(K.size()));
  if (K[1] != 0) w.fail(field, "has skew (K[0][1] = " + std::to_string(K[1]) + "): not read");
  if (K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
    w.fail(field, "is not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]");
  fx = K[0];
  fy = K[4];
  cx = K[2];
  cy = K[5];
  if (!(fx > 0) || !(fy > 0)) w.fail(field, "focal lengths must be positive");
}

// The camera from a distortion model and its coefficients.
CameraDescription camera(const std::string& model, const std::vector<double>& d, double fx,
                         double fy, double cx, double cy, int width, int height,
                         const std::string& field, const Where& w) {
  CameraDescription c;
  c.width = width;
  c.height = height;
  if (model == "plumb_bob" || model == "radtan" || model == "radial-tangential") {
    if (d.size() != 4 && d.size() != 5)
      w.fail(field, model + " needs 4 or 5 coefficients (k1 k2 p1 p2 [k3]), has " +
                        std::to_string(d.size()));
    c.model = CameraModelKind::pinhole;
    c.pinhole = {fx, fy, cx, cy, {d[0], d[1], d[2], d[3], d.size() == 5 ? d[4] : 0.0}};
  } else if (model == "rational_polynomial") {
    if (d.size() != 8)
      w.fail(field, "rational_polynomial needs 8 coefficients, has " + std::to_string(d.size()));
    if (d[5] != 0 || d[6] != 0 || d[7] != 0)
      w.fail(field,
             "rational_polynomial with k4, k5 or k6 not zero is not read (robot.json's "
             "pinhole has k1 k2 p1 p2 k3)");
    c.model = CameraModelKind::pinhole;
    c.pinhole = {fx, fy, cx, cy, {d[0], d[1], d[2], d[3], d[4]}};
  } else if (model == "equidistant" || model == "fisheye" || model == "pinhole-equi") {
    if (d.size() != 4)
      w.fail(field, model + " needs 4 coefficients (k1 k2 k3 k4), has " + std::to_string(d.size()));
    c.model = CameraModelKind::kannala_brandt;
    c.fisheye.f = fx;
    c.fisheye.beta = fy / fx;
    c.fisheye.u0 = cx;
    c.fisheye.v0 = cy;
    c.fisheye.k = {d[0], d[1], d[2], d[3]};
    c.fisheye.fov_deg = 180;
  } else {
    w.fail(field, "distortion model '" + model +
                      "' is not read (plumb_bob, radtan, rational_polynomial, equidistant)");
  }
  return c;
}

}  // namespace

std::vector<ImportedCamera> read_calibration(const std::string& path) {
  return parse_calibration(json::read_file(path), path);
}

std::vector<ImportedCamera> parse_calibration(const std::string& data, const std::string& path) {
  Node root;
  // OpenCV's YAML is YAML but for its first line's directive ("%YAML:1.0", not YAML's
  // "%YAML 1.0"): read by yaml-cpp with that line made a comment (line numbers kept), like the
  // other YAML files.
  const bool opencv_yaml = data.rfind("%YAML:1.", 0) == 0;
  const auto xml_at = data.find("<?xml");
  if (xml_at != std::string::npos && xml_at < 16) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(data.data(), data.size()) != tinyxml2::XML_SUCCESS) {
      // "XML_ERROR_PARSING_ATTRIBUTE" said as "error parsing attribute".
      std::string what = doc.ErrorName();
      if (what.rfind("XML_", 0) == 0) what.erase(0, 4);
      for (char& c : what) c = c == '_' ? ' ' : char(std::tolower(static_cast<unsigned char>(c)));
      throw InputError({path, "line " + std::to_string(doc.ErrorLineNum()), ""},
                       "not a YAML or XML calibration file: XML " + what);
    }
    const tinyxml2::XMLElement* storage = doc.RootElement();
    if (!storage || std::string(storage->Name()) != "opencv_storage")
      throw InputError({path, "", ""}, "an XML calibration file is OpenCV's <opencv_storage>");
    root = from_xml(*storage, path);
    if (root.kind == Node::none) root.kind = Node::map;  // <opencv_storage/>: no keys
  } else {
    try {
      root = from_yaml(YAML::Load(opencv_yaml ? "#" + data : data), path);
    } catch (const YAML::Exception& e) {
      throw InputError({path, "line " + std::to_string(e.mark.line + 1), ""},
                       "not a YAML or XML calibration file: " + e.msg);
    }
  }
  if (root.kind != Node::map)
    throw InputError({path, "", ""}, "a calibration file holds a map of keys");
  std::vector<ImportedCamera> out;
  Where w{path, ""};
  if (!root["camera_matrix"].empty() && !root["distortion_model"].empty()) {
    // ROS camera_info.
    ImportedCamera ic;
    ic.format = "ROS camera_info";
    w.place = root["camera_name"].kind == Node::scalar ? root["camera_name"].text : "";
    ic.label = w.place;
    double fx, fy, cx, cy;
    from_matrix(numbers(root["camera_matrix"], "camera_matrix", w), "camera_matrix", w, fx, fy, cx,
                cy);
    ic.camera = camera(
        text(root["distortion_model"], "distortion_model", w),
        numbers(need(root, "distortion_coefficients", w), "distortion_coefficients", w), fx, fy, cx,
        cy, pixels(need(root, "image_width", w), "image_width", w),
        pixels(need(root, "image_height", w), "image_height", w), "distortion_coefficients", w);
    out.push_back(std::move(ic));
  } else if (!root["camera_matrix"].empty()) {
    // OpenCV's calibration sample.
    ImportedCamera ic;
    ic.format = "OpenCV";
    double fx, fy, cx, cy;
    from_matrix(numbers(root["camera_matrix"], "camera_matrix", w), "camera_matrix", w, fx, fy, cx,
                cy);
    const std::vector<double> d =
        numbers(need(root, "distortion_coefficients", w), "distortion_coefficients", w);
    const bool fisheye =
        !root["fisheye_model"].empty() && number(root["fisheye_model"], "fisheye_model", w) != 0;
    const std::string model = fisheye         ? "fisheye"
                              : d.size() == 8 ? "rational_polynomial"
                                              : "plumb_bob";
    ic.camera = camera(
        model, d, fx, fy, cx, cy, pixels(need(root, "image_width", w), "image_width", w),
        pixels(need(root, "image_height", w), "image_height", w), "distortion_coefficients", w);
    out.push_back(std::move(ic));
  } else {
    // Kalibr camchain: cam0, cam1, ...
    for (int k = 0;; ++k) {
      const std::string key = "cam" + std::to_string(k);
      const Node& cam = root[key];
      if (cam.empty()) break;
      w.place = key;
      if (cam.kind != Node::map) w.fail("", "must be a map");
      ImportedCamera ic;
      ic.format = "Kalibr camchain";
      ic.label = key;
      if (cam["rostopic"].kind == Node::scalar) ic.label += " (" + cam["rostopic"].text + ")";
      const std::string projection = text(need(cam, "camera_model", w), "camera_model", w);
      if (projection != "pinhole")
        w.fail("camera_model",
               "'" + projection + "' is not read (pinhole, with radtan or equidistant distortion)");
      const std::vector<double> in = numbers(need(cam, "intrinsics", w), "intrinsics", w);
      if (in.size() != 4) w.fail("intrinsics", "must be [fu, fv, pu, pv]");
      if (!(in[0] > 0) || !(in[1] > 0)) w.fail("intrinsics", "focal lengths must be positive");
      const std::vector<double> res = numbers(need(cam, "resolution", w), "resolution", w);
      if (res.size() != 2 || res[0] < 1 || res[1] < 1 || res[0] != std::floor(res[0]) ||
          res[1] != std::floor(res[1]) || res[0] > 100000 || res[1] > 100000)
        w.fail("resolution", "must be [width, height] in pixels");
      ic.camera = camera(text(need(cam, "distortion_model", w), "distortion_model", w),
                         numbers(need(cam, "distortion_coeffs", w), "distortion_coeffs", w), in[0],
                         in[1], in[2], in[3], int(res[0]), int(res[1]), "distortion_coeffs", w);
      out.push_back(std::move(ic));
    }
    if (out.empty())
      throw InputError({path, "", ""},
                       "not a calibration lampnav reads: no camera_matrix (ROS camera_info, "
                       "OpenCV) and no cam0 (Kalibr camchain)");
  }
  return out;
}

std::optional<CameraDescription> camera_from_info(const CameraInfo& info,
                                                  const std::string& source) {
  if (std::all_of(info.k.begin(), info.k.end(), [](double v) { return v == 0; }))
    return std::nullopt;
  const Where w{source, info.frame_id};
  const std::vector<double> K(info.k.begin(), info.k.end());
  for (const auto& [values, field] : {std::pair{&K, "k"}, std::pair{&info.d, "d"}})
    if (!std::all_of(values->begin(), values->end(), [](double v) { return std::isfinite(v); }))
      w.fail(field, "holds a number that is not finite");
  double fx, fy, cx, cy;
  from_matrix(K, "k", w, fx, fy, cx, cy);
  if (info.width <= 0 || info.height <= 0 || info.width > 100000 || info.height > 100000)
    w.fail("width", "the image size must be 1 to 100000 px each way");
  return camera(info.distortion_model, info.d, fx, fy, cx, cy, info.width, info.height, "d", w);
}

}  // namespace lampnav::io
