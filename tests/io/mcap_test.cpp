#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "lampnav/core/error.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav_test.hpp"

namespace lampnav::io {
namespace {

using ::testing::HasSubstr;

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("lampnav_mcap_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

using test::slurp;

// Writes a small mission-like file: two channels, interleaved messages, two attachments.
std::string write_sample(const std::string& name, McapWriterOptions opt, int messages = 40) {
  const std::string path = temp_file(name);
  McapWriter w(path, opt);
  const auto s = w.add_schema("lampnav.WheelOdometry", "jsonschema", R"({"type":"object"})");
  const auto wheels = w.add_channel(s, "/wheels", "json");
  const auto events = w.add_channel(s, "/events", "json", {{"note", "test"}});
  w.attach({0, 0, "robot.json", "application/json", R"({"name":"r"})"});
  for (int i = 0; i < messages; ++i) {
    const std::uint64_t t = 1'000'000'000ULL + static_cast<std::uint64_t>(i) * 10'000'000ULL;
    w.write(wheels, t, t, R"({"left":)" + std::to_string(i) + "}");
    if (i % 10 == 0) w.write(events, t + 5, t, R"({"kind":"tick"})");
  }
  w.attach({0, 0, "map.geojson", "application/geo+json", std::string(300, 'x')});
  w.close();
  return path;
}

class McapRoundTrip : public ::testing::TestWithParam<int> {};

TEST_P(McapRoundTrip, EveryLayoutReadsBack) {
  McapWriterOptions opt;
  switch (GetParam()) {
    case 0:
      opt.compression = McapCompression::zstd;
      opt.chunk_size = 256;
      break;
    case 1:
      opt.compression = McapCompression::none;
      opt.chunk_size = 256;
      break;
    case 2:
      opt.chunked = false;
      break;
    case 3:
      opt.chunked = false;
      opt.summary = false;
      break;
    case 4:
      opt.summary = false;
      opt.chunk_size = 256;
      break;
  }
  const std::string path = write_sample("rt" + std::to_string(GetParam()), opt);
  const McapFile f = read_mcap(path);
  EXPECT_FALSE(f.report.truncated);
  EXPECT_TRUE(f.report.problems.empty()) << f.report.problems.front();
  EXPECT_EQ(f.report.has_summary, opt.summary);
  EXPECT_EQ(f.library, "lampnav 0.1.0");
  ASSERT_EQ(f.channels.size(), 2u);
  EXPECT_EQ(f.channel("/events")->metadata.at("note"), "test");
  EXPECT_EQ(f.schema(f.channel("/wheels")->schema_id)->name, "lampnav.WheelOdometry");
  ASSERT_EQ(f.messages.size(), 44u);
  int wheels = 0;
  for (const auto& m : f.messages) {
    if (m.channel_id != f.channel("/wheels")->id) continue;
    EXPECT_EQ(m.sequence, static_cast<std::uint32_t>(wheels));
    EXPECT_EQ(m.data, R"({"left":)" + std::to_string(wheels) + "}");
    ++wheels;
  }
  EXPECT_EQ(wheels, 40);
  ASSERT_NE(f.attachment("map.geojson"), nullptr);
  EXPECT_EQ(f.attachment("map.geojson")->data, std::string(300, 'x'));
  EXPECT_EQ(f.attachment("robot.json")->media_type, "application/json");
  if (opt.chunked) {
    EXPECT_GT(f.report.chunks, 1u);
  }
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(Layouts, McapRoundTrip, ::testing::Range(0, 5));

// Cut the file at every byte: never a crash, the recovered messages only grow with the cut, the
// cut is reported, and all are back once the data section is whole.
TEST(McapTruncation, EveryByteOffset) {
  for (McapCompression c : {McapCompression::none, McapCompression::zstd}) {
    McapWriterOptions opt;
    opt.compression = c;
    opt.chunk_size = 200;
    const std::string path =
        write_sample(c == McapCompression::none ? "cut_raw" : "cut_zstd", opt, 20);
    const std::string bytes = slurp(path);
    std::size_t last = 0;
    for (std::size_t cut = 8; cut < bytes.size(); ++cut) {
      McapFile f;
      try {
        f = read_mcap_bytes(bytes.substr(0, cut), "cut.mcap");
      } catch (const InputError& e) {
        // Only a cut inside the header may refuse the file outright.
        EXPECT_LT(cut, 40u) << e.what();
        continue;
      }
      EXPECT_TRUE(f.report.truncated) << "cut at " << cut;
      EXPECT_GE(f.messages.size(), last) << "cut at " << cut;
      last = f.messages.size();
      for (std::size_t i = 0; i < f.messages.size(); ++i) {
        EXPECT_EQ(f.messages[i].channel_id == f.channel("/wheels")->id,
                  f.messages[i].data.rfind(R"({"left":)", 0) == 0);
      }
    }
    EXPECT_EQ(last, 22u);  // everything once the data section is complete
    std::filesystem::remove(path);
  }
}

TEST(McapTruncation, UncompressedChunkGivesUpItsCompleteMessages) {
  McapWriterOptions opt;
  opt.compression = McapCompression::none;
  opt.chunk_size = 1 << 20;  // one big chunk
  const std::string path = write_sample("salvage", opt, 40);
  const std::string bytes = slurp(path);
  // Cut in the middle of the file: the chunk is incomplete but holds complete messages.
  const McapFile f = read_mcap_bytes(bytes.substr(0, bytes.size() / 2), "half.mcap");
  EXPECT_TRUE(f.report.truncated);
  EXPECT_THAT(f.report.truncation, HasSubstr("Chunk"));
  EXPECT_GT(f.messages.size(), 5u);
  std::filesystem::remove(path);
}

TEST(McapReader, RefusesWhatIsNotMcap) {
  EXPECT_THROW(read_mcap("/nonexistent.mcap"), InputError);
  try {
    read_mcap_bytes("PK\x03\x04 not an mcap at all", "zip.mcap");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "zip.mcap");
    EXPECT_EQ(e.where().place, "byte 0");
    EXPECT_THAT(e.message(), HasSubstr("bad magic"));
  }
  EXPECT_THROW(read_mcap_bytes("\x89MC", "short.mcap"), InputError);
}

TEST(McapReader, DamageIsCountedAndReported) {
  McapWriterOptions opt;
  opt.chunked = false;
  const std::string path = write_sample("damage", opt, 10);
  std::string bytes = slurp(path);
  // Flip the attachment data so its CRC fails, and turn the first message's opcode into an
  // unknown one: both are skipped, counted and reported, the rest is read.
  const auto at = bytes.find("xxxxxxxx");
  bytes[at] = 'y';
  const auto msg = bytes.find(R"({"left":0})");
  const std::size_t record_start = msg - 9 - 2 - 4 - 8 - 8;
  ASSERT_EQ(bytes[record_start], '\x05');
  bytes[record_start] = '\x42';
  const McapFile f = read_mcap_bytes(bytes, "damaged.mcap");
  EXPECT_EQ(f.report.skipped_records, 2u);
  ASSERT_EQ(f.report.problems.size(), 2u);
  EXPECT_THAT(f.report.problems[0], HasSubstr("unknown record opcode 0x42"));
  EXPECT_THAT(f.report.problems[1], HasSubstr("fails its CRC check"));
  EXPECT_EQ(f.messages.size(), 10u);  // 10 wheel readings and 1 event, less the damaged one
  EXPECT_EQ(f.attachment("map.geojson"), nullptr);
  std::filesystem::remove(path);
}

TEST(McapReader, RandomGarbageNeverCrashes) {
  std::mt19937 rng(11);
  McapWriterOptions opt;
  opt.chunk_size = 128;
  const std::string bytes = slurp(write_sample("fuzz", opt, 20));
  for (int i = 0; i < 3000; ++i) {
    std::string b = bytes;
    const int flips = 1 + static_cast<int>(rng() % 8);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] = static_cast<char>(rng());
    try {
      const McapFile f = read_mcap_bytes(b, "fuzz.mcap");
      for (const auto& m : f.messages) EXPECT_NE(f.channel(m.channel_id), nullptr);
    } catch (const InputError&) {
      // refused with a message: fine
    }
  }
}

TEST(Crc32, KnownValue) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(s.data(), s.size()), 0xCBF43926u);
}

}  // namespace
}  // namespace lampnav::io

// What Foxglove would refuse is refused when writing, or written as it expects.
namespace lampnav::io {
namespace {

TEST(MissionLogWriter, RefusesANegativeTimeAndWritesJpegAsJpeg) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_writer_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  {
    MissionLogWriter w(path);
    // Foxglove's time is unsigned: a stamp before 1970 cannot be written, and nothing is.
    EXPECT_THROW(w.write(Stamp(std::chrono::seconds(1)),
                         WheelReading{Stamp(std::chrono::seconds(-1)), 0, 0}),
                 InputError);
    w.write(Stamp(std::chrono::seconds(1)), WheelReading{Stamp(std::chrono::seconds(1)), 0.5, 0.5});
    w.write_image(Stamp(std::chrono::seconds(2)),
                  ImageFrame{Stamp(std::chrono::seconds(2)), "ceiling_camera", "jpg", "xyz"});
    w.close();
  }
  const McapFile f = read_mcap(path);
  std::size_t wheels = 0;
  bool jpeg = false;
  std::map<std::uint16_t, std::string> topic_of;
  for (const auto& c : f.channels) topic_of[c.id] = c.topic;
  for (const auto& m : f.messages) {
    const std::string& topic = topic_of.at(m.channel_id);
    if (topic == topics::kWheels) ++wheels;
    if (topic == topics::kCeilingImage)
      jpeg = m.data.find(R"("format":"jpeg")") != std::string::npos;
  }
  EXPECT_EQ(wheels, 1u);
  EXPECT_TRUE(jpeg);
  std::filesystem::remove(path);
}

// Events are typed for programs, and a word of another tool comes back as it was written.
TEST(MissionLog, EventKindsAreTypedAndOtherToolsWordsKept) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_events_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  const Stamp t(std::chrono::seconds(3));
  {
    MissionLogWriter w(path);
    w.write(t, WheelReading{t, 0, 0});
    w.write(t, MissionEvent{t, EventKind::kidnap, "to C3"});
    w.write(t, MissionEvent{t, "door_opened", "D2"});
    w.close();
  }
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  ASSERT_EQ(log.events.size(), 2u);
  EXPECT_EQ(log.events[0].value.type(), EventKind::kidnap);
  EXPECT_EQ(log.events[0].value.kind, "kidnap");
  EXPECT_EQ(log.events[0].value.detail, "to C3");
  EXPECT_EQ(log.events[1].value.type(), EventKind::other);
  EXPECT_EQ(log.events[1].value.kind, "door_opened");
  EXPECT_EQ(event_kind("frame_drop"), EventKind::frame_drop);
  EXPECT_STREQ(to_string(EventKind::lamp_failure), "lamp_failure");
}

}  // namespace
}  // namespace lampnav::io
