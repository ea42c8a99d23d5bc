#include "lampnav/evaluation/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/internal/json_util.hpp"

namespace lampnav::evaluation {

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string num(double v, int digits = 2) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

// About n points, evenly spaced, keeping the gaps and the points on either side of each.
std::vector<std::pair<double, double>> thin(const std::vector<std::pair<double, double>>& v,
                                            std::size_t n) {
  if (v.size() <= n) return v;
  const std::size_t stride = (v.size() + n - 1) / n;
  auto gap = [&](std::size_t k) { return k < v.size() && !std::isfinite(v[k].first); };
  std::vector<std::pair<double, double>> out;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (k % stride == 0 || k + 1 == v.size() || gap(k) || gap(k + 1) || (k > 0 && gap(k - 1)))
      out.push_back(v[k]);
  return out;
}

// Polylines through the points, broken where a point is not finite (a gap: a kidnap's jump, a
// stretch lost).
template <class ToX, class ToY>
std::string polylines(const std::vector<std::pair<double, double>>& pts, const std::string& attrs,
                      ToX X, ToY Y) {
  std::string out, cur;
  int n = 0;
  auto flush = [&] {
    if (n >= 2) out += "<polyline fill=\"none\" " + attrs + " points=\"" + cur + "\"/>\n";
    cur.clear();
    n = 0;
  };
  for (const auto& [x, y] : pts) {
    if (!std::isfinite(x) || !std::isfinite(y)) {
      flush();
      continue;
    }
    cur += X(x) + "," + Y(y) + " ";
    ++n;
  }
  flush();
  return out;
}

const std::pair<double, double> kGap{std::numeric_limits<double>::quiet_NaN(),
                                     std::numeric_limits<double>::quiet_NaN()};

struct Series {
  std::string name, color;
  std::vector<std::pair<double, double>> points;
  bool dashed = false;
};

struct Interval {
  double from, to;
  std::string color;
};

// A time-series chart with axes, ticks, shaded intervals and a legend.
std::string line_chart(const std::vector<Series>& series, const std::string& x_label,
                       const std::string& y_label, const std::vector<Interval>& shaded,
                       bool log_y = false) {
  const double W = 900, H = 260, L = 70, R = 20, T = 20, B = 45;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  auto ty = [&](double y) { return log_y ? std::log10(std::max(y, 1e-12)) : y; };
  for (const auto& s : series)
    for (const auto& [x, y] : s.points) {
      if (!std::isfinite(y)) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, ty(y));
      y1 = std::max(y1, ty(y));
    }
  if (!std::isfinite(x0)) {
    x0 = 0;
    x1 = 1;
    y0 = 0;
    y1 = 1;
  }
  if (log_y) {
    // Whole decades, at most six below the largest value.
    y1 = std::ceil(y1);
    y0 = std::max(std::floor(y0), y1 - 6);
  } else {
    y0 = std::min(0.0, y0);
  }
  if (y1 - y0 < 1e-9) y1 = y0 + 1;
  if (x1 - x0 < 1e-9) x1 = x0 + 1;
  if (!log_y) y1 += 0.05 * (y1 - y0);
  auto px = [&](double x) { return L + (x - x0) / (x1 - x0) * (W - L - R); };
  auto py = [&](double y) {
    return H - B - (std::clamp(ty(y), y0, y1) - y0) / (y1 - y0) * (H - T - B);
  };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " << W << " " << H
    << "\" width=\"100%\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect x=\"0\" y=\"0\" width=\"" << W << "\" height=\"" << H << "\" fill=\"white\"/>\n";
  for (const auto& iv : shaded)
    s << "<rect x=\"" << num(px(iv.from), 1) << "\" y=\"" << T << "\" width=\""
      << num(std::max(1.0, px(iv.to) - px(iv.from)), 1) << "\" height=\"" << H - T - B
      << "\" fill=\"" << iv.color << "\" fill-opacity=\"0.25\"/>\n";
  // Axes and ticks.
  s << "<line x1=\"" << L << "\" y1=\"" << H - B << "\" x2=\"" << W - R << "\" y2=\"" << H - B
    << "\" stroke=\"#333\"/>\n<line x1=\"" << L << "\" y1=\"" << T << "\" x2=\"" << L << "\" y2=\""
    << H - B << "\" stroke=\"#333\"/>\n";
  for (int k = 0; k <= 5; ++k) {
    const double xv = x0 + k * (x1 - x0) / 5;
    s << "<text x=\"" << num(px(xv), 1) << "\" y=\"" << H - B + 16 << "\" text-anchor=\"middle\">"
      << num(xv, 0) << "</text>\n";
  }
  const int y_ticks = log_y ? static_cast<int>(std::lround(y1 - y0)) : 5;
  for (int k = 0; k <= y_ticks; ++k) {
    const double yv = y0 + k * (y1 - y0) / y_ticks;
    const double ypix = H - B - k * (H - T - B) / static_cast<double>(y_ticks);
    std::string label = num(yv, yv < 10 ? 2 : 0);
    if (log_y) {
      char b10[32];
      std::snprintf(b10, sizeof b10, "%g", std::pow(10.0, std::lround(yv)));
      label = b10;
    }
    s << "<text x=\"" << L - 6 << "\" y=\"" << num(ypix + 4, 1) << "\" text-anchor=\"end\">"
      << label << "</text>\n"
      << "<line x1=\"" << L << "\" y1=\"" << num(ypix, 1) << "\" x2=\"" << W - R << "\" y2=\""
      << num(ypix, 1) << "\" stroke=\"#ddd\"/>\n";
  }
  s << "<text x=\"" << (L + W - R) / 2 << "\" y=\"" << H - 8 << "\" text-anchor=\"middle\">"
    << escape(x_label) << "</text>\n"
    << "<text x=\"14\" y=\"" << (T + H - B) / 2
    << "\" text-anchor=\"middle\" transform=\"rotate(-90 14 " << (T + H - B) / 2 << ")\">"
    << escape(y_label) << "</text>\n";
  int legend = 0;
  for (const auto& se : series) {
    if (se.points.empty()) continue;
    s << polylines(
        thin(se.points, 1500),
        "stroke=\"" + se.color + "\" stroke-width=\"1.5\"" +
            (se.dashed ? " stroke-dasharray=\"5,3\"" : ""),
        [&](double x) { return num(px(x), 1); }, [&](double y) { return num(py(y), 1); });
    s << "<rect x=\"" << W - R - 200 << "\" y=\"" << T + 4 + 16 * legend
      << "\" width=\"12\" height=\"3\" fill=\"" << se.color << "\"/><text x=\"" << W - R - 183
      << "\" y=\"" << T + 9 + 16 * legend << "\">" << escape(se.name) << "</text>\n";
    ++legend;
  }
  s << "</svg>\n";
  return s.str();
}

// A place on the map where something happened: a kidnap (red) or a relocalization (green).
struct Mark {
  enum class Kind { kidnap, relocalized };
  Eigen::Vector2d at;
  Kind kind;
};

// The map with regions, axes, lamps, names and trajectories.
std::string map_figure(const graph::TopologicalMap& map, const std::vector<Series>& paths,
                       const std::vector<Mark>& marks) {
  Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
  for (const auto& n : map.nodes()) {
    for (const auto& v : n.region.vertices()) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    lo = lo.cwiseMin(n.point);
    hi = hi.cwiseMax(n.point);
  }
  const double W = 900, pad = 20;
  const double scale = (W - 2 * pad) / std::max(1e-6, hi.x() - lo.x());
  const double H = std::max(200.0, (hi.y() - lo.y()) * scale + 2 * pad);
  auto X = [&](double x) { return num(pad + (x - lo.x()) * scale, 1); };
  auto Y = [&](double y) { return num(H - pad - (y - lo.y()) * scale, 1); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " << W << " " << num(H, 0)
    << "\" width=\"100%\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"" << W
    << "\" height=\"" << num(H, 0) << "\" fill=\"white\"/>\n";
  for (const auto& n : map.nodes()) {
    if (n.region.size() < 3) continue;
    const bool room = n.place == graph::Place::room || n.place == graph::Place::hall;
    s << "<polygon fill=\"" << (room ? "#eef2f7" : "#f6f6f6") << "\" stroke=\"#9aa5b5\" points=\"";
    for (const auto& v : n.region.vertices()) s << X(v.x()) << "," << Y(v.y()) << " ";
    s << "\"/>\n";
  }
  for (const auto& n : map.nodes()) {
    if (n.axis)
      s << "<line x1=\"" << X(n.axis->first.x()) << "\" y1=\"" << Y(n.axis->first.y()) << "\" x2=\""
        << X(n.axis->second.x()) << "\" y2=\"" << Y(n.axis->second.y())
        << "\" stroke=\"#c5cde0\" stroke-dasharray=\"4,3\"/>\n";
    for (const auto& l : n.lamps)
      s << "<circle cx=\"" << X(l.xyz.x()) << "\" cy=\"" << Y(l.xyz.y())
        << "\" r=\"2.5\" fill=\"#f2b705\"/>\n";
    s << "<text x=\"" << X(n.point.x()) << "\" y=\"" << Y(n.point.y())
      << "\" fill=\"#778\" text-anchor=\"middle\">" << escape(n.name) << "</text>\n";
  }
  int legend = 0;
  for (const auto& p : paths) {
    if (p.points.empty()) continue;
    s << polylines(thin(p.points, 3000),
                   "stroke=\"" + p.color + "\" stroke-width=\"2\"" +
                       (p.dashed ? " stroke-dasharray=\"6,4\"" : ""),
                   X, Y)
      << "<rect x=\"" << pad + 4 << "\" y=\"" << pad + 16 * legend
      << "\" width=\"14\" height=\"4\" fill=\"" << p.color << "\"/><text x=\"" << pad + 24
      << "\" y=\"" << pad + 6 + 16 * legend << "\">" << escape(p.name) << "</text>\n";
    ++legend;
  }
  for (const Mark& m : marks) {
    const bool kidnap = m.kind == Mark::Kind::kidnap;
    s << "<circle cx=\"" << X(m.at.x()) << "\" cy=\"" << Y(m.at.y())
      << "\" r=\"6\" fill=\"none\" stroke=\"" << (kidnap ? "#d62728" : "#2ca02c")
      << "\" stroke-width=\"2\"><title>" << (kidnap ? "kidnap" : "relocalized")
      << "</title></circle>\n";
  }
  s << "</svg>\n";
  return s.str();
}

bool unsure(fusion::LocalizerMode m) { return !fusion::is_certain(m); }

// Stretches lost (red) and ambiguous (orange).
std::vector<Interval> lost_intervals(const ReplayResult& r, double t0) {
  std::vector<Interval> out;
  std::optional<double> from;
  fusion::LocalizerMode mode = fusion::LocalizerMode::tracking;
  auto color = [](fusion::LocalizerMode m) {
    return m == fusion::LocalizerMode::lost ? "#d62728" : "#ff7f0e";
  };
  for (const auto& e : r.estimates) {
    const double t = to_seconds(e.stamp) - t0;
    if (from && e.mode != mode) {
      out.push_back({*from, t, color(mode)});
      from.reset();
    }
    if (unsure(e.mode) && !from) {
      from = t;
      mode = e.mode;
    }
  }
  if (from && !r.estimates.empty())
    out.push_back({*from, to_seconds(r.estimates.back().stamp) - t0, color(mode)});
  return out;
}

}  // namespace

std::vector<Figure> report_figures(const ReplayResult& r, const io::MissionLog& log,
                                   const graph::TopologicalMap& map) {
  const double t0 = log.wheels.empty() ? 0.0 : to_seconds(log.wheels.front().value.stamp);
  const io::TruthTrack truth(log.truth);
  Series truth_path{"truth", "#2ca02c", {}}, odo{"odometry only", "#999999", {}, true},
      fused{"fused estimate", "#1f77b4", {}};
  const Pose2* before = nullptr;
  for (const auto& s : truth.samples()) {
    if (before && (s.value.pose.translation() - before->translation()).norm() > 0.5)
      truth_path.points.push_back(kGap);  // lifted and carried
    truth_path.points.emplace_back(s.value.pose.x(), s.value.pose.y());
    before = &s.value.pose;
  }
  for (const auto& [t, p] : r.odometry) odo.points.emplace_back(p.x(), p.y());
  for (const auto& e : r.estimates) {
    if (unsure(e.mode)) {
      if (!fused.points.empty() && std::isfinite(fused.points.back().first))
        fused.points.push_back(kGap);
      continue;
    }
    fused.points.emplace_back(e.pose.x(), e.pose.y());
  }
  std::vector<Mark> marks;
  for (const auto& e : log.events)
    if (e.value.type() == io::EventKind::kidnap && !truth.empty())
      marks.push_back({truth.at(e.value.stamp + std::chrono::milliseconds(1)).translation(),
                       Mark::Kind::kidnap});
  for (const auto& e : r.events)
    if (e.mode == fusion::LocalizerMode::relocalized)
      for (const auto& s : r.estimates)
        if (s.stamp > e.stamp) {
          marks.push_back({s.pose.translation(), Mark::Kind::relocalized});
          break;
        }
  std::vector<Figure> figs;
  figs.push_back({"map.svg",
                  "The map, with the true, odometry-only and fused trajectories (red rings: "
                  "kidnaps; green rings: relocalizations)",
                  map_figure(map, {truth_path, odo, fused}, marks)});
  const auto lost = lost_intervals(r, t0);
  if (!truth.empty()) {
    Series pos{"fused", "#1f77b4", {}}, pos_odo{"odometry only", "#999999", {}, true},
        yaw{"fused", "#1f77b4", {}}, yaw_odo{"odometry only", "#999999", {}, true};
    for (const auto& e : r.estimates) {
      const Pose2 t = truth.at(e.stamp);
      const double ts = to_seconds(e.stamp) - t0;
      if (unsure(e.mode)) {
        if (!pos.points.empty() && std::isfinite(pos.points.back().first)) {
          pos.points.push_back(kGap);
          yaw.points.push_back(kGap);
        }
        continue;
      }
      pos.points.emplace_back(ts, (e.pose.translation() - t.translation()).norm());
      yaw.points.emplace_back(ts, std::fabs(wrap_angle(e.pose.yaw() - t.yaw())) / kDeg);
    }
    for (const auto& [s, p] : r.odometry) {
      const Pose2 t = truth.at(s);
      const double ts = to_seconds(s) - t0;
      pos_odo.points.emplace_back(ts, (p.translation() - t.translation()).norm());
      yaw_odo.points.emplace_back(ts, std::fabs(wrap_angle(p.yaw() - t.yaw())) / kDeg);
    }
    figs.push_back({"position_error.svg", "Position error against the truth (red: lost)",
                    line_chart({pos, pos_odo}, "time (s)", "position error (m)", lost, true)});
    figs.push_back({"heading_error.svg", "Heading error against the truth (red: lost)",
                    line_chart({yaw, yaw_odo}, "time (s)", "heading error (deg)", lost, true)});
  }
  Series norm{"|P| (Frobenius)", "#9467bd", {}};
  for (const auto& e : r.estimates)
    norm.points.emplace_back(to_seconds(e.stamp) - t0, fusion::covariance_norm(e.covariance));
  figs.push_back({"covariance.svg", "Norm of the covariance over time (paper 2, Fig. 7; red: lost)",
                  line_chart({norm}, "time (s)", "covariance norm", lost, true)});
  if (!r.hypotheses.empty()) {
    // How many places the robot may be, and the leader's share (1 once one pose is known).
    Series count{"hypotheses", "#ff7f0e", {}}, share{"leader's weight x 10", "#1f77b4", {}};
    for (const auto& h : r.hypotheses) {
      const double ts = to_seconds(h.stamp) - t0;
      const bool known = !unsure(h.mode);
      const double n = known ? 1.0 : static_cast<double>(h.hypotheses.size());
      const double w = known ? 1.0 : h.hypotheses.empty() ? 0.0 : h.hypotheses.front().weight;
      if (!count.points.empty()) {  // steps: the value holds until the next change
        count.points.emplace_back(ts, count.points.back().second);
        share.points.emplace_back(ts, share.points.back().second);
      }
      count.points.emplace_back(ts, n);
      share.points.emplace_back(ts, 10 * w);
    }
    figs.push_back({"hypotheses.svg",
                    "Places the robot may be, and the leader's share of the weight (red: lost; "
                    "orange: ambiguous)",
                    line_chart({count, share}, "time (s)", "hypotheses", lost)});
  }
  Series seen{"lamps seen", "#ff7f0e", {}}, labelled{"labelled", "#1f77b4", {}};
  for (const auto& f : r.lamp_frames) {
    int l = 0;
    for (const auto& o : f.observations.lamps) l += o.label ? 1 : 0;
    const double ts = to_seconds(f.observations.stamp) - t0;
    seen.points.emplace_back(ts, f.observations.lamps.size());
    labelled.points.emplace_back(ts, l);
  }
  if (!r.lamp_frames.empty())
    figs.push_back({"lamps.svg", "Ceiling lamps seen and labelled per frame (red: lost)",
                    line_chart({seen, labelled}, "time (s)", "lamps", lost)});
  return figs;
}

std::string report_html(const ReplayResult& r, const io::MissionLog& log,
                        const std::vector<Figure>& figures, const std::string& title) {
  const Metrics& m = r.metrics;
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
    << escape(title) << "</title>\n<style>\n"
    << "body{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}\n"
    << "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px "
       "10px;text-align:left}\n"
    << "figure{margin:1.5em 0}figcaption{color:#555;margin-top:.3em}\n"
    << ".ok{color:#2ca02c}.bad{color:#d62728}\n</style>\n</head>\n<body>\n<h1>" << escape(title)
    << "</h1>\n";
  auto row = [&](const std::string& k, const std::string& v) {
    h << "<tr><th>" << escape(k) << "</th><td>" << v << "</td></tr>\n";
  };
  h << "<h2>Metrics</h2>\n<table id=\"metrics\">\n";
  row("duration", num(m.duration_s, 1) + " s");
  row("frames", std::to_string(m.frames) + " (" + std::to_string(m.ceiling_frames) + " ceiling, " +
                    std::to_string(m.omni_frames) + " omni)");
  if (m.has_truth && m.position_error_m.n) {
    row("position error (outside lost intervals)",
        "mean " + num(m.position_error_m.mean * 100) + " cm, RMS " +
            num(m.position_error_m.rms * 100) + " cm, max " + num(m.position_error_m.max * 100) +
            " cm");
    row("heading error", "mean " + num(m.yaw_error_deg.mean) + "&deg;, RMS " +
                             num(m.yaw_error_deg.rms) + "&deg;, max " + num(m.yaw_error_deg.max) +
                             "&deg;");
  } else if (m.has_truth) {
    row("errors", "not scored: no pose was ever published as tracking");
  } else {
    row("errors", "not scored: the log has no truth");
  }
  if (m.has_truth) row("wrong fixes (certain, more than 0.5 m off)", std::to_string(m.wrong_fixes));
  row("time lost", num(m.lost_s, 1) + " s");
  row("time ambiguous (one of several places)", num(m.ambiguous_s, 1) + " s");
  row("kidnaps / recoveries", std::to_string(m.kidnaps) + " / " + std::to_string(m.recoveries));
  if (m.relocalization_latency_s.n)
    row("relocalization latency", "mean " + num(m.relocalization_latency_s.mean) + " s, max " +
                                      num(m.relocalization_latency_s.max) + " s");
  row("ceiling lamps seen / labelled",
      std::to_string(m.lamps_seen) + " / " + std::to_string(m.lamps_labelled));
  row("replay", num(m.runtime_s, 2) + " s, " + num(m.realtime_factor, 1) + "x real time");
  h << "</table>\n<h2>Notes</h2>\n<ul>\n";
  for (const auto& n : r.notes) h << "<li>" << escape(n) << "</li>\n";
  h << "</ul>\n<h2>Lost and relocalized</h2>\n<ul id=\"events\">\n";
  const double t0 = log.wheels.empty() ? 0.0 : to_seconds(log.wheels.front().value.stamp);
  for (const auto& e : log.events)
    if (e.value.type() == io::EventKind::kidnap)
      h << "<li class=\"bad\">" << num(to_seconds(e.value.stamp) - t0, 2) << " s: kidnapped ("
        << escape(e.value.detail) << ")</li>\n";
  for (const auto& e : r.events)
    h << "<li class=\"" << (unsure(e.mode) ? "bad" : "ok") << "\">"
      << num(to_seconds(e.stamp) - t0, 2) << " s: " << fusion::to_string(e.mode) << " ("
      << escape(e.reason) << ")</li>\n";
  h << "</ul>\n<h2>Figures</h2>\n";
  for (const auto& f : figures)
    h << "<figure id=\"" << f.file.substr(0, f.file.find('.')) << "\">\n"
      << f.svg << "<figcaption>" << escape(f.title) << "</figcaption>\n</figure>\n";
  h << "</body>\n</html>\n";
  return h.str();
}

void write_report(const ReplayResult& r, const io::MissionLog& log,
                  const graph::TopologicalMap& map, const std::string& title,
                  const std::string& dir) {
  const std::vector<Figure> figures = report_figures(r, log, map);
  json::write_file(dir + "/report.html", report_html(r, log, figures, title));
  for (const auto& f : figures) json::write_file(dir + "/" + f.file, f.svg);
}

}  // namespace lampnav::evaluation
