// Interoperability is proven, not assumed: our files are read by the official TypeScript MCAP
// reader (@mcap/core, indexed reader), installed by `make test` into tests/interop.

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>

#include "lampnav/io/mcap.hpp"
#include "lampnav_test.hpp"

namespace lampnav::io {
namespace {

using ::testing::HasSubstr;

std::string run_node_reader(const std::string& file, int* status) {
  const std::string dir = test::source_path("tests/interop");
  return test::run_command("cd '" + dir + "' && node read_mcap.mjs '" + file + "' 2>&1", status);
}

class McapInterop : public ::testing::TestWithParam<McapCompression> {};

TEST_P(McapInterop, OfficialReaderSeesTopicsCountsAndAttachments) {
  ASSERT_TRUE(std::filesystem::exists(test::source_path("tests/interop/node_modules/@mcap/core")))
      << "@mcap/core is not installed: run `make test`, which installs it";
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_interop_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  {
    McapWriterOptions opt;
    opt.compression = GetParam();
    opt.chunk_size = 4096;
    McapWriter w(path, opt);
    const auto odo = w.add_schema("lampnav.WheelOdometry", "jsonschema", R"({"type":"object"})");
    const auto img = w.add_schema("foxglove.CompressedImage", "jsonschema", R"({"type":"object"})");
    const auto wheels = w.add_channel(odo, "/wheels", "json");
    const auto cam = w.add_channel(img, "/ceiling_camera/image", "json");
    w.attach({0, 0, "robot.json", "application/json", R"({"name":"pioneer-2at"})"});
    w.attach({0, 0, "map.geojson", "application/geo+json", std::string(5000, ' ')});
    for (int i = 0; i < 500; ++i) {
      const std::uint64_t t =
          1'000'000'000ULL * 100 + static_cast<std::uint64_t>(i) * 20'000'000ULL;
      w.write(wheels, t, t, R"({"left":)" + std::to_string(i * 0.01) + "}");
      if (i % 25 == 0) w.write(cam, t + 1'000'000'000ULL, t, R"({"format":"png","data":""})");
    }
    w.close();
  }
  int status = -1;
  const std::string out = run_node_reader(path, &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_THAT(out, HasSubstr(R"("library":"lampnav 0.1.0")"));
  EXPECT_THAT(
      out,
      HasSubstr(R"("/wheels":{"schema":"lampnav.WheelOdometry","encoding":"json","count":500})"));
  EXPECT_THAT(
      out,
      HasSubstr(
          R"("/ceiling_camera/image":{"schema":"foxglove.CompressedImage","encoding":"json","count":20})"));
  EXPECT_THAT(out, HasSubstr(R"("logTimeOrdered":true)"));
  EXPECT_THAT(out, HasSubstr(R"("messageCount":520)"));
  EXPECT_THAT(out, HasSubstr(R"({"name":"robot.json","mediaType":"application/json","size":22})"));
  EXPECT_THAT(
      out, HasSubstr(R"({"name":"map.geojson","mediaType":"application/geo+json","size":5000})"));
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(Compression, McapInterop,
                         ::testing::Values(McapCompression::none, McapCompression::zstd));

}  // namespace
}  // namespace lampnav::io
