// `make bench`'s one table: reads the JSON the benchmark programs wrote, prints case, ours, peer,
// ratio and target, each row saying plainly whether its target is met, with how costs grow with the
// building's size; writes the same as bench/results.json.
//   bench_summary OUT.json BENCH.json...

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Json = nlohmann::ordered_json;

struct Measure {
  double us = 0;  // real time per iteration, microseconds
  Json raw;
};

std::map<std::string, Measure> results;
Json context;

void read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  const Json j = Json::parse(in);
  if (context.is_null()) context = j["context"];
  for (const auto& b : j["benchmarks"]) {
    const std::string unit = b.value("time_unit", "ns");
    const double f = unit == "ns" ? 1e-3 : unit == "us" ? 1.0 : unit == "ms" ? 1e3 : 1e6;
    std::string name = b["name"];
    // "BM_X/iterations:3/real_time" -> "BM_X"
    for (const char* tail : {"/iterations:", "/real_time", "/min_time:"}) {
      const auto p = name.find(tail);
      if (p != std::string::npos) name = name.substr(0, p);
    }
    results[name] = {b["real_time"].get<double>() * f, b};
  }
}

std::optional<double> us(const std::string& name) {
  auto it = results.find(name);
  if (it == results.end()) return std::nullopt;
  return it->second.us;
}

std::string show(double v_us) {
  std::ostringstream s;
  s << std::setprecision(3);
  if (v_us < 1)
    s << v_us * 1000 << " ns";
  else if (v_us < 1000)
    s << v_us << " us";
  else if (v_us < 1e6)
    s << v_us / 1000 << " ms";
  else
    s << v_us / 1e6 << " s";
  return s.str();
}

struct Row {
  std::string what, ours, peer, ratio, target, verdict;
};
std::vector<Row> rows;
Json out_rows = Json::array();

void add(const std::string& what, std::optional<double> ours_us, const std::string& peer_label,
         std::optional<double> peer_us, std::optional<double> max_us,
         std::optional<double> min_ratio) {
  Row r{what, ours_us ? show(*ours_us) : "not run", "", "", "", ""};
  Json j{{"case", what}, {"ours_us", ours_us ? Json(*ours_us) : Json(nullptr)}};
  std::vector<std::string> missed;
  if (peer_us && ours_us) {
    const double ratio = *peer_us / *ours_us;
    r.peer = peer_label + " " + show(*peer_us);
    std::ostringstream s;
    s << std::setprecision(3) << ratio << "x";
    r.ratio = s.str();
    j["peer"] = peer_label;
    j["peer_us"] = *peer_us;
    j["ratio"] = ratio;
    if (min_ratio && ratio < *min_ratio) missed.push_back("ratio");
  }
  std::string target;
  if (max_us) {
    target = "<= " + show(*max_us);
    j["target_max_us"] = *max_us;
    if (!ours_us || *ours_us > *max_us) missed.push_back("time");
  }
  if (min_ratio) {
    std::ostringstream s;
    s << (target.empty() ? "" : ", ") << ">= " << *min_ratio << "x peer";
    target += s.str();
    j["target_min_ratio"] = *min_ratio;
  }
  r.target = target;
  if (!max_us && !min_ratio)
    r.verdict = "";
  else
    r.verdict = missed.empty() ? "met" : "MISSED";
  j["met"] = (max_us || min_ratio) ? Json(missed.empty()) : Json(nullptr);
  rows.push_back(r);
  out_rows.push_back(j);
}

void add_counter(const std::string& what, const std::string& bench, const std::string& counter,
                 double min_value, const std::string& unit) {
  Row r{what, "not run", "", "", ">= " + std::to_string(static_cast<int>(min_value)) + unit, ""};
  Json j{{"case", what}};
  auto it = results.find(bench);
  if (it != results.end() && it->second.raw.contains(counter)) {
    const double v = it->second.raw[counter].get<double>();
    std::ostringstream s;
    s << std::setprecision(3) << v << unit;
    r.ours = s.str();
    r.verdict = v >= min_value ? "met" : "MISSED";
    j["ours"] = v;
    j["unit"] = unit;
    j["target_min"] = min_value;
    j["met"] = v >= min_value;
  } else {
    r.verdict = "MISSED";
    j["met"] = false;
  }
  rows.push_back(r);
  out_rows.push_back(j);
}

// A counter of a benchmark, as microseconds when `to_us` says how.
std::optional<double> counter(const std::string& bench, const std::string& name, double to_us) {
  const auto it = results.find(bench);
  if (it == results.end() || !it->second.raw.contains(name)) return std::nullopt;
  return it->second.raw[name].get<double>() * to_us;
}

// A measured value (not a time) against a peer's, with an upper bound (a file's size), or, with
// `tolerance`, a value that must stay within it of the peer's (an accuracy that must not change).
void add_value(const std::string& what, std::optional<double> ours, const std::string& peer_label,
               std::optional<double> peer, std::optional<double> max_value,
               std::optional<double> tolerance, const std::string& unit) {
  auto show_value = [&](double v) {
    std::ostringstream s;
    s << std::setprecision(3) << v << " " << unit;
    return s.str();
  };
  Row r{what, ours ? show_value(*ours) : "not run", "", "", "", ""};
  Json j{{"case", what}, {"ours", ours ? Json(*ours) : Json(nullptr)}, {"unit", unit}};
  bool met = ours.has_value();
  if (peer) {
    r.peer = peer_label + ": " + show_value(*peer);
    j["peer"] = peer_label;
    j["peer_value"] = *peer;
    if (ours && *ours > 0) {
      std::ostringstream s;
      s << std::setprecision(3) << *peer / *ours << "x";
      r.ratio = s.str();
    }
  }
  if (max_value) {
    r.target = "<= " + show_value(*max_value);
    j["target_max"] = *max_value;
    met = met && *ours <= *max_value;
  }
  if (tolerance) {
    r.target = "within " + show_value(*tolerance) + " of " + peer_label;
    j["tolerance"] = *tolerance;
    met = met && peer && std::fabs(*ours - *peer) <= *tolerance;
  }
  r.verdict = met ? "met" : "MISSED";
  j["met"] = met;
  rows.push_back(r);
  out_rows.push_back(j);
}

// A count that must stay at or below `max_value` (messages lost).
void add_count(const std::string& what, std::optional<double> v, double max_value) {
  Row r{what, v ? std::to_string(static_cast<long long>(*v)) : "not run", "",
        "",   "<= " + std::to_string(static_cast<long long>(max_value)),  ""};
  r.verdict = v && *v <= max_value ? "met" : "MISSED";
  rows.push_back(r);
  out_rows.push_back({{"case", what},
                      {"ours", v ? Json(*v) : Json(nullptr)},
                      {"target_max", max_value},
                      {"met", v && *v <= max_value}});
}

// A localization battery (bench/localization_bench.cpp): every episode relocalized to the true
// place (kidnaps: detected too) and not one wrong fix; the latency beside it.
void add_battery(const std::string& what, const std::string& bench, bool kidnaps) {
  Row r{what,
        "not run",
        "",
        "",
        kidnaps ? "all detected, all right, 0 wrong" : "all right, 0 wrong",
        "MISSED"};
  Json j{{"case", what}};
  auto it = results.find(bench);
  if (it != results.end() && it->second.raw.contains("episodes")) {
    const Json& c = it->second.raw;
    const int n = c["episodes"].get<double>(), d = c["detected"].get<double>(),
              ok = c["correct"].get<double>(), wrong = c["wrong_fixes"].get<double>();
    std::ostringstream s;
    s << std::setprecision(3);
    if (kidnaps) s << d << "/" << n << " detected, ";
    s << ok << "/" << n << " right, " << wrong << " wrong; latency p50 "
      << c["latency_s_median"].get<double>() << " s / " << c["latency_m_median"].get<double>()
      << " m, p95 " << c["latency_s_p95"].get<double>() << " s / "
      << c["latency_m_p95"].get<double>() << " m";
    r.ours = s.str();
    const bool met = ok == n && wrong == 0 && (!kidnaps || d == n);
    r.verdict = met ? "met" : "MISSED";
    j["ours"] = c;
    j["met"] = met;
  } else {
    j["met"] = false;
  }
  rows.push_back(r);
  out_rows.push_back(j);
  // Against the map oracle (sim::MapOracle): relocalized right within its distance plus 10 m.
  if (it != results.end() && it->second.raw.contains("within_oracle_10m")) {
    const Json& c = it->second.raw;
    const int n = c["episodes"].get<double>(), in = c["within_oracle_10m"].get<double>(),
              decided = c["oracle_decided"].get<double>();
    std::ostringstream s;
    s << std::setprecision(3) << in << "/" << n << " (oracle decided " << decided
      << "); past it p50 " << c["past_oracle_m_median"].get<double>() << " m, p95 "
      << c["past_oracle_m_p95"].get<double>() << " m";
    rows.push_back({"  right within the oracle's distance + 10 m", s.str(), "", "", "all",
                    in == n ? "met" : "MISSED"});
    out_rows.push_back({{"case", what + ": within the oracle's distance + 10 m"},
                        {"ours", in},
                        {"episodes", n},
                        {"met", in == n}});
  }
  // The localizer's time per camera frame while unsure, with the hypotheses it weighed.
  if (it != results.end() && it->second.raw.contains("unsure_us_per_frame")) {
    const Json& c = it->second.raw;
    std::ostringstream name;
    name << std::setprecision(3) << "  localizer per frame while unsure ("
         << c["unsure_mean_hypotheses"].get<double>() << " hypotheses on average)";
    add(name.str(), c["unsure_us_per_frame"].get<double>(), "", std::nullopt, 2000.0, std::nullopt);
  }
  // The target's own case: frames that found 50 to 200 live hypotheses ("100").
  if (it != results.end() && it->second.raw.contains("frames_50_200_hypotheses") &&
      it->second.raw["frames_50_200_hypotheses"].get<double>() > 0) {
    const Json& c = it->second.raw;
    std::ostringstream name;
    name << std::setprecision(3) << "  localizer per frame with 50 to 200 hypotheses ("
         << c["mean_hypotheses_of_those"].get<double>() << " on average, "
         << c["frames_50_200_hypotheses"].get<double>() << " frames)";
    add(name.str(), c["us_per_frame_50_200_hypotheses"].get<double>(), "", std::nullopt, 2000.0,
        std::nullopt);
  }
}

// How a cost grows with the building: the exponent of n between 100 and 1,000 nodes.
Json growth = Json::object();
void grows(const std::string& what, const std::string& bench) {
  const auto a = us(bench + "/100"), b = us(bench + "/1000");
  if (!a || !b || *a <= 0) return;
  const double e = std::log(*b / *a) / std::log(10.0);
  growth[what] = e;
  std::ostringstream s;
  s << std::setprecision(2) << "grows as n^" << e << " (100 to 1,000 nodes)";
  rows.push_back({"  " + what, s.str(), "", "", "", ""});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: bench_summary OUT.json BENCH.json...\n";
    return 2;
  }
  try {
    for (int k = 2; k < argc; ++k) read(argv[k]);
  } catch (const std::exception& e) {
    std::cerr << "bench_summary: " << e.what() << "\n";
    return 2;
  }
  for (const char* px : {"352", "640"}) {
    const std::string p = px, size = p == "352" ? "352x288" : "640x480";
    const auto ours = us("BM_LampDetectAndTrack/" + p);
    // Issue 18: windowed tracking at most 10 us at 352x288 (8 times SimpleBlobDetector with one
    // threshold) and 30 us at 640x480.
    const bool small = p == "352";
    add("ceiling detection + tracking (windowed), " + size, ours,
        "SimpleBlobDetector (1 threshold)", us("BM_OpenCvSimpleBlobDetector/" + p),
        small ? 10.0 : 30.0, small ? std::optional<double>(8.0) : std::nullopt);
    add("ceiling detection + tracking (windowed), " + size, ours,
        "SimpleBlobDetector (default sweep)", us("BM_OpenCvSimpleBlobDetectorSweep/" + p),
        std::nullopt, std::nullopt);
    add("ceiling detection + tracking (windowed), " + size, ours, "every frame read whole",
        us("BM_LampDetectAndTrackWholeFrames/" + p), std::nullopt, std::nullopt);
    add("ceiling detection + tracking, " + size, ours, "vpDot2::searchDotsInArea",
        us("BM_VispSearchDotsInArea/" + p), std::nullopt, std::nullopt);
  }
  add("omni detection, 1024x1024", us("BM_OmniDetector/0"), "paper's pipeline on OpenCV",
      us("BM_PaperOmniPipelineOpenCv"), 2000.0, std::nullopt);
  add("omni detection, 1024x1024, office corridors (blooms)", us("BM_OmniDetector/1"), "",
      std::nullopt, 2000.0, std::nullopt);
  add("omni frame decoding, 1024x1024, JPEG 90", us("BM_DecodeOmniFrame/90"),
      "PNG of the same frames", us("BM_DecodeOmniFrame/0"), std::nullopt, std::nullopt);
  int raw = 0;
  for (const char* encoding : {"mono8", "bgr8", "yuyv", "bayer_rggb8"})
    add(std::string("omni frame made grey, 1024x1024, raw ") + encoding,
        us("BM_ReadRawOmniFrame/" + std::to_string(raw++)), "JPEG 90 decoding",
        us("BM_DecodeOmniFrame/90"), std::nullopt, std::nullopt);
  add("EKF predict", us("BM_EkfPredict"), "", std::nullopt, 0.1, std::nullopt);
  const auto pu = us("BM_EkfPredictAndGatedUpdate"), pr = us("BM_EkfPredict");
  add("EKF gated update (predict + update minus predict)",
      pu && pr ? std::optional<double>(*pu - *pr) : std::nullopt, "", std::nullopt, 0.5,
      std::nullopt);
  add("EKF measurement 1 s late at 100 Hz", us("BM_EkfLateUpdateOneSecond"), "", std::nullopt, 20.0,
      std::nullopt);
  add("global localization, paper (2502 merits), museum", us("BM_GlobalLocalizationPaper"), "",
      std::nullopt, 2000.0, std::nullopt);
  add("global localization, default, museum", us("BM_GlobalLocalizationDefault"), "paper",
      us("BM_GlobalLocalizationPaper"), 5000.0, std::nullopt);
  for (const char* n : {"10", "100", "1000"})
    add(std::string("global localization, default, ") + n + "-node building",
        us(std::string("BM_GlobalLocalizationBuilding/") + n), "", std::nullopt,
        std::string(n) == "1000" ? std::optional<double>(50000.0) : std::nullopt, std::nullopt);
  grows("global localization", "BM_GlobalLocalizationBuilding");
  for (const char* n : {"10", "100", "1000"})
    add(std::string("map load and validation, ") + n + "-node building",
        us(std::string("BM_BuildingMapLoad/") + n), "", std::nullopt,
        std::string(n) == "1000" ? std::optional<double>(200000.0) : std::nullopt, std::nullopt);
  grows("map load", "BM_BuildingMapLoad");
  for (const char* n : {"10", "100", "1000"})
    add(std::string("route planning, corner to corner, ") + n + "-node building",
        us(std::string("BM_BuildingRoutePlanning/") + n), "", std::nullopt,
        std::string(n) == "1000" ? std::optional<double>(1000.0) : std::nullopt, std::nullopt);
  grows("route planning", "BM_BuildingRoutePlanning");
  for (const char* n : {"10", "100", "1000"})
    add(std::string("which node holds a point, ") + n + "-node building",
        us(std::string("BM_BuildingWhichNode/") + n), "", std::nullopt, std::nullopt, std::nullopt);
  grows("which-node query", "BM_BuildingWhichNode");
  add_counter("replay of the office mission (140 s)", "BM_ReplayOfficeMission", "realtime_factor",
              150, "x real time");
  // The office mission's log: frames as JPEG at the default quality (argument 50) against PNG.
  add_value("office mission log (140 s), JPEG 50", counter("BM_OfficeMissionLog/50", "log_MB", 1),
            "PNG", counter("BM_OfficeMissionLog/0", "log_MB", 1), 20.0, std::nullopt, "MB");
  add_value("office mission replay from the JPEG log, mean position error",
            counter("BM_OfficeMissionLog/50", "mean_error_cm", 1), "PNG",
            counter("BM_OfficeMissionLog/0", "mean_error_cm", 1), std::nullopt, 0.1, "cm");
  for (const char* n : {"10", "100", "1000"})
    add_counter(std::string("replay of a 6-minute mission, ") + n + "-node building",
                std::string("BM_ReplayBuildingMission/") + n, "realtime_factor", 50, "x real time");
  grows("replay", "BM_ReplayBuildingMission");
  add("map build from a recorded 10-minute drive (100-node building)", us("BM_MapBuildFromLog/5"),
      "", std::nullopt, 20e6, std::nullopt);
  // The maps of the five buildings' 10-minute drives: corner to corner (no loop), and as one loop
  // (the drive docs/mapping.md asks for).
  for (const auto& [benchmark, name] :
       {std::pair{"BM_MapBuildFromLog/", "drive"}, {"BM_MapBuildFromLoop/", "loop"}})
    for (const char* seed : {"5", "11", "23", "31", "64"}) {
      const std::string bench = std::string(benchmark) + seed;
      const std::string drive = std::string("map of a 10-minute ") + name + ", building " + seed;
      add_value(drive + ", lamp position RMS", counter(bench, "rms_cm", 1), "", std::nullopt, 2.0,
                std::nullopt, "cm");
      add_value(drive + ", lamp position max", counter(bench, "max_cm", 1), "", std::nullopt, 5.0,
                std::nullopt, "cm");
      add_value(drive + ", lamp height max", counter(bench, "height_max_cm", 1), "", std::nullopt,
                3.0, std::nullopt, "cm");
      add_value(drive + ", lamps seen but left out of every place",
                counter(bench, "lamps_outside", 1), "", std::nullopt, 0.0, std::nullopt, "lamps");
      // The scale, which no camera looking up can see, taken out: what the mapping itself leaves.
      add_value(drive + ", lamp position RMS, scale taken out", counter(bench, "rms_scaled_cm", 1),
                "", std::nullopt, std::nullopt, std::nullopt, "cm");
      add_value(drive + ", lamp position max, scale taken out", counter(bench, "max_scaled_cm", 1),
                "", std::nullopt, std::nullopt, std::nullopt, "cm");
      // Built again with two distances measured down corridors (map build --distance).
      add_value(drive + ", with 2 distances measured, lamp position RMS",
                counter(bench, "measured_rms_cm", 1), "", std::nullopt, 2.0, std::nullopt, "cm");
      add_value(drive + ", with 2 distances measured, lamp position max",
                counter(bench, "measured_max_cm", 1), "", std::nullopt, 5.0, std::nullopt, "cm");
    }
  for (const auto& [arg, format] : {std::pair{"0/0", "PNG"},
                                    {"90/0", "JPEG 90"},
                                    {"90/1", "JPEG 90, start pose given"},
                                    {"-1/0", "raw mono8"},
                                    {"-1/1", "raw mono8, start pose given"},
                                    {"-2/1", "raw yuyv, start pose given"}}) {
    const std::string bench = std::string("BM_NodeImageToPose/") + arg;
    for (const char* camera : {"ceiling", "omni"})
      for (const char* q : {"p50", "p99"})
        add(std::string("node: ") + camera + " image (" + format + ") in to pose out, " + q,
            counter(bench, std::string(camera) + "_" + q + "_ms", 1000), "", std::nullopt,
            std::string(q) == "p99" ? std::optional<double>(5000) : std::nullopt, std::nullopt);
    // What of the omni p99 is the node's own work (from the decoded image on): the rest is
    // decoding and waiting for a core.
    add(std::string("  of which decoded omni image to pose out, p99"),
        counter(bench, "omni_work_p99_ms", 1000), "", std::nullopt, std::nullopt, std::nullopt);
    // Omni images that gave no pose, only hypotheses: the start not found yet, the first of
    // them searching the whole map. No pose, so not in the rows above.
    if (std::string(arg).back() == '0')
      add(std::string("  omni images before the start was found (no pose out), the slowest to "
                      "hypotheses out"),
          counter(bench, "omni_searching_max_ms", 1000), "", std::nullopt, std::nullopt,
          std::nullopt);
    add_count(std::string("node: messages lost (") + format + ", 30 Hz images, 150 Hz odometry)",
              counter(bench, "lost", 1), 0);
  }
  for (const auto& [n, count] : {std::pair{"10", "100"}, {"100", "100"}, {"1000", "100"}})
    add_battery(std::string("kidnaps (") + count + "), " + n + "-node building",
                std::string("BM_KidnapBattery/") + n + "/" + count, true);
  add("  the same 100-node kidnaps, hypotheses weighed on one core: per frame with 50 to 200",
      counter("BM_KidnapBatteryOneCore/100/100", "us_per_frame_50_200_hypotheses", 1), "",
      std::nullopt, std::nullopt, std::nullopt);
  for (const auto& [n, count] : {std::pair{"10", "20"}, {"100", "20"}, {"1000", "20"}})
    add_battery(std::string("unknown starts (") + count + "), " + n + "-node building",
                std::string("BM_UnknownStartBattery/") + n + "/" + count, false);
  add_battery(
      "kidnaps (50), 100-node building, the floor swinging the cameras 1.5 deg (swing learnt)",
      "BM_KidnapBatteryOnARoughFloor/100/50/1", true);
  add_battery("  the same kidnaps, the lamps weighed for the configured 0.5 deg",
              "BM_KidnapBatteryOnARoughFloor/100/50/0", true);
  add_battery("kidnaps (50), 100-node building of round lamps 4.5 m apart",
              "BM_RoundLampsFarApartBattery/100/50/1", true);
  add_battery("unknown starts (20), the same building", "BM_RoundLampsFarApartBattery/100/20/0",
              false);
  for (const auto& [args, what] : {std::pair{"30/0/0", "its lamps 3 cm off (sigma)"},
                                   {"50/0/0", "its lamps 5 cm off (sigma)"},
                                   {"0/5/0", "5 % of the lamps not in it"},
                                   {"0/0/10", "10 % of its lamps out"},
                                   {"30/2/5", "its lamps 3 cm off, 2 % not in it, 5 % out"}})
    add_battery(std::string("unknown starts (20), 100-node building, a map with ") + what,
                std::string("BM_UnknownStartsOnAnImperfectMap/") + args, false);

  std::size_t w[5] = {4, 4, 4, 5, 6};
  for (const auto& r : rows) {
    w[0] = std::max(w[0], r.what.size());
    w[1] = std::max(w[1], r.ours.size());
    w[2] = std::max(w[2], r.peer.size());
    w[3] = std::max(w[3], r.ratio.size());
    w[4] = std::max(w[4], r.target.size());
  }
  auto line = [&](const Row& r) {
    std::cout << std::left << std::setw(w[0] + 2) << r.what << std::setw(w[1] + 2) << r.ours
              << std::setw(w[2] + 2) << r.peer << std::setw(w[3] + 2) << r.ratio
              << std::setw(w[4] + 2) << r.target << r.verdict << "\n";
  };
  line({"case", "ours", "peer", "ratio", "target", ""});
  for (const auto& r : rows) line(r);
  int missed = 0;
  for (const auto& r : rows) missed += r.verdict == "MISSED";
  std::cout << "\n" << missed << " target(s) missed\n";
  Json out{{"machine",
            {{"host", context.value("host_name", "")},
             {"cpus", context.value("num_cpus", 0)},
             {"mhz_per_cpu", context.value("mhz_per_cpu", 0)},
             {"date", context.value("date", "")},
             {"build", context.value("library_build_type", "")}}},
           {"rows", out_rows},
           {"growth_exponent_100_to_1000_nodes", growth},
           {"targets_missed", missed}};
  std::ofstream(argv[1]) << out.dump(2) << "\n";
  return 0;
}
