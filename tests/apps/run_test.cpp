// The main job end to end: `lampnav run` drives the office mission and writes its outputs;
// `lampnav replay` runs the stack over the log it wrote; the report opens in headless Chromium
// with no console error and shows its figures.

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "lampnav_test.hpp"

namespace lampnav {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct Result {
  int status = -1;
  std::string out, err;
};

Result lampnav(const std::string& args) {
  const std::string err_file =
      (fs::temp_directory_path() / ("lampnav_run_err_" + std::to_string(::getpid()))).string();
  Result r;
  r.out = test::run_command(std::string(LAMPNAV_BINARY) + " " + args + " 2>" + err_file, &r.status);
  r.err = test::slurp(err_file);
  fs::remove(err_file);
  return r;
}

// One `lampnav run` for the tests below.
struct MainJob {
  std::string dir =
      (fs::temp_directory_path() / ("lampnav_main_" + std::to_string(::getpid()))).string();
  Result run;
  MainJob() { run = lampnav("run -q --out '" + dir + "'"); }
  ~MainJob() { fs::remove_all(dir); }
};

const MainJob& main_job() {
  static const MainJob j;
  return j;
}

// One run per test process (it drives a 140 s mission): its outputs, its replay, its report.
TEST(MainJob, RunThenReplayThenReport) {
  const MainJob& j = main_job();
  ASSERT_EQ(j.run.status, 0) << j.run.err;
  EXPECT_THAT(j.run.out, HasSubstr("arrived at Workshop"));
  EXPECT_THAT(j.run.out, HasSubstr("real time"));
  for (const char* f : {"mission.mcap", "replay.mcap", "estimate.tum", "truth.tum", "metrics.json",
                        "report.html", "map.svg", "position_error.svg", "covariance.svg"})
    EXPECT_TRUE(fs::exists(j.dir + "/" + f)) << f;
  const auto m = nlohmann::json::parse(test::slurp(j.dir + "/metrics.json"));
  EXPECT_LE(m["position_error_m"]["mean"].get<double>(), 0.05);
  EXPECT_EQ(m["kidnaps"], 1);
  EXPECT_EQ(m["recoveries"], 1);
  {
    SCOPED_TRACE("replay without being told where the robot starts");

    const std::string out = j.dir + "/again";
    const Result r = lampnav("replay -q '" + j.dir + "/mission.mcap' --out '" + out + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("localized globally from the omni camera first"));
    const auto again = nlohmann::json::parse(test::slurp(out + "/metrics.json"));
    EXPECT_LE(again["position_error_m"]["mean"].get<double>(), 0.05);
    EXPECT_EQ(again["recoveries"], 1);
  }
  {
    SCOPED_TRACE("the report in headless Chromium");

    ASSERT_TRUE(fs::exists("/usr/bin/chromium")) << "scripts/install-deps.sh installs chromium";
    const std::string shot = j.dir + "/report.png", log = j.dir + "/chromium.log";
    const std::string cmd =
        "timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic "
        "--no-first-run --disable-background-networking --disable-component-update --disable-sync "
        "--user-data-dir='" +
        j.dir +
        "/profile' --enable-logging=stderr --v=0 --hide-scrollbars "
        "--window-size=1000,2600 --screenshot='" +
        shot + "' 'file://" + j.dir + "/report.html' 2>'" + log + "'";
    int status = -1;
    test::run_command(cmd, &status);
    ASSERT_EQ(status, 0) << test::slurp(log);
    // No console message at all (the page has no script): no error.
    EXPECT_THAT(test::slurp(log), ::testing::Not(HasSubstr("CONSOLE"))) << test::slurp(log);
    const cv::Mat img = cv::imread(shot, cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty());
    // The figures' colours are on the page: the fused trajectory, the truth, the covariance.
    auto count = [&](int r, int g, int b) {
      int n = 0;
      for (int y = 0; y < img.rows; ++y)
        for (int x = 0; x < img.cols; ++x) {
          const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
          if (std::abs(p[2] - r) < 12 && std::abs(p[1] - g) < 12 && std::abs(p[0] - b) < 12) ++n;
        }
      return n;
    };
    EXPECT_GT(count(0x1f, 0x77, 0xb4), 2000);  // fused estimate
    EXPECT_GT(count(0x2c, 0xa0, 0x2c), 200);   // truth
    EXPECT_GT(count(0x94, 0x67, 0xbd), 500);   // covariance norm
    const std::string html = test::slurp(j.dir + "/report.html");
    for (const char* id : {"id=\"map\"", "id=\"position_error\"", "id=\"heading_error\"",
                           "id=\"covariance\"", "id=\"lamps\"", "id=\"metrics\"", "id=\"events\""})
      EXPECT_THAT(html, HasSubstr(id));
    EXPECT_THAT(html, ::testing::Not(HasSubstr("<script")));
    EXPECT_THAT(html, ::testing::Not(HasSubstr("src=")));  // self-contained
  }
}

TEST(MainJob, BadInputExitsTwoSayingWhy) {
  const Result missing = lampnav("replay /nonexistent.mcap");
  EXPECT_EQ(missing.status, 2);
  EXPECT_THAT(missing.err, HasSubstr("/nonexistent.mcap"));
  const std::string text =
      (fs::temp_directory_path() / ("lampnav_notmcap_" + std::to_string(::getpid()))).string();
  std::ofstream(text) << "hello";
  const Result garbage = lampnav("replay '" + text + "'");
  EXPECT_EQ(garbage.status, 2);
  EXPECT_THAT(garbage.err, HasSubstr(text));
  fs::remove(text);
  const Result pose = lampnav("replay /nonexistent.mcap --initial-pose 1,2");
  EXPECT_EQ(pose.status, 2);
  EXPECT_THAT(pose.err, HasSubstr("--initial-pose"));
  const Result mission = lampnav("run --mission domus-kidnap");
  EXPECT_EQ(mission.status, 2);
  EXPECT_THAT(mission.err, HasSubstr("cannot be driven"));
}

}  // namespace
}  // namespace lampnav
