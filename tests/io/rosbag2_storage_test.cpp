// ROS 2 bags in rosbag2's sqlite3 storage (.db3), read without ROS: a bag rosbag2 itself wrote
// (tests/fixtures/rosbag2, NOTICE.md), by its file, its directory and its bytes; bags split into
// files, compressed message by message or whole, and damaged, written as rosbag2 lays them out.

#include "rosbag2_storage.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "lampnav/core/error.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav_test.hpp"
#include "rosbag2_writer.hpp"

namespace lampnav::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The topic of each message and, for std_msgs/msg/String, its text.
std::vector<std::string> contents(const McapFile& f) {
  std::vector<std::string> out;
  for (const auto& m : f.messages) {
    const McapChannel* ch = f.channel(m.channel_id);
    const McapSchema* s = ch ? f.schema(ch->schema_id) : nullptr;
    std::string line = (ch ? ch->topic : "?") + " " + (s ? s->name : "?");
    if (s && s->name == "std_msgs/msg/String") line += " " + ros2::string_data(m.data);
    out.push_back(line);
  }
  return out;
}

TEST(Rosbag2Storage, ReadsTheBagRosbag2Wrote) {
  // Copied so that nothing SQLite might make beside it lands in the source tree.
  const std::string dir = test::temp_path("rosbag2_talker");
  fs::remove_all(dir);
  fs::copy(test::source_path("tests/fixtures/rosbag2/talker"), dir);
  std::vector<std::string> notes;
  const McapFile file = read_log_container(dir + "/talker.db3", notes);
  EXPECT_TRUE(notes.empty());
  ASSERT_EQ(file.channels.size(), 3u);
  ASSERT_EQ(file.messages.size(), 20u);
  for (const auto& ch : file.channels) EXPECT_EQ(ch.message_encoding, "cdr") << ch.topic;
  const std::vector<std::string> got = contents(file);
  std::vector<std::string> said;
  for (const auto& line : got)
    if (line.rfind("/topic ", 0) == 0) said.push_back(line);
  ASSERT_EQ(said.size(), 10u);
  for (int k = 0; k < 10; ++k)
    EXPECT_EQ(said[k], "/topic std_msgs/msg/String Hello, world! " + std::to_string(k));
  EXPECT_EQ(
      std::count_if(got.begin(), got.end(),
                    [](const std::string& l) { return l == "/rosout rcl_interfaces/msg/Log"; }),
      10);
  for (std::size_t k = 1; k < file.messages.size(); ++k)
    EXPECT_LE(file.messages[k - 1].log_time, file.messages[k].log_time);
  EXPECT_EQ(file.messages.front().log_time, 1585866235112411371u);  // metadata.yaml's start

  // The same through the bag's directory (metadata.yaml), and from its bytes in memory.
  const McapFile by_dir = read_log_container(dir, notes);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("sqlite3 storage"));
  EXPECT_EQ(contents(by_dir), got);
  EXPECT_EQ(contents(read_sqlite_bag_bytes(slurp(dir + "/talker.db3"), "talker")), got);
  // Read as it was: no file made beside it.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);

  // As a mission log: a ROS 2 bag with nothing lampnav drives by, said so.
  const MissionLog log = read_mission_log(dir);
  EXPECT_TRUE(log.ros2_bag);
  EXPECT_TRUE(log.wheels.empty());
  std::string all;
  for (const auto& n : log.notes) all += n + "\n";
  EXPECT_THAT(all, HasSubstr("rosbag2 bag (sqlite3 storage), 1 file"));
  EXPECT_THAT(all, HasSubstr("the bag gives no wheel odometry"));
  fs::remove_all(dir);
}

TEST(Rosbag2Storage, SplitAndCompressedBagsReadAsOne) {
  const std::string dir = test::temp_path("rosbag2_split");
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Three files as --max-bag-size splits them; the second compressed message by message, the
  // third as a whole file; the topics numbered differently in each.
  auto say = [](int k) { return ros2::string_message("message " + std::to_string(k)); };
  {
    test::Rosbag2SqliteWriter a(dir + "/bag_0.db3");
    const auto chatter = a.topic("/chatter", "std_msgs/msg/String");
    for (int k = 0; k < 4; ++k) a.write(chatter, 1000 + k, say(k));
  }
  {
    test::Rosbag2SqliteWriter b(dir + "/bag_1.db3");
    b.topic("/other", "std_msgs/msg/String");
    const auto chatter = b.topic("/chatter", "std_msgs/msg/String");
    for (int k = 4; k < 8; ++k) b.write(chatter, 1000 + k, say(k), true);
  }
  {
    test::Rosbag2SqliteWriter c(dir + "/whole.db3");
    const auto chatter = c.topic("/chatter", "std_msgs/msg/String");
    for (int k = 8; k < 12; ++k) c.write(chatter, 1000 + k, say(k));
  }
  std::ofstream(dir + "/bag_2.db3.zstd", std::ios::binary)
      << test::Rosbag2SqliteWriter::zstd(slurp(dir + "/whole.db3"));
  fs::remove(dir + "/whole.db3");
  std::ofstream(dir + "/metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: sqlite3\n"
         "  relative_file_paths:\n    - bag_0.db3\n    - bag_1.db3\n    - bag_2.db3.zstd\n"
         "  compression_format: zstd\n  compression_mode: FILE\n";
  std::vector<std::string> notes;
  const McapFile f = read_log_container(dir, notes);
  ASSERT_EQ(f.channels.size(), 2u);
  std::vector<std::string> want;
  for (int k = 0; k < 12; ++k)
    want.push_back("/chatter std_msgs/msg/String message " + std::to_string(k));
  EXPECT_EQ(contents(f), want);
  EXPECT_EQ(f.report.skipped_records, 0u);

  // Without metadata.yaml: the files in the order of their numbers (bag_10 after bag_2).
  fs::remove(dir + "/metadata.yaml");
  {
    test::Rosbag2SqliteWriter d(dir + "/bag_10.db3");
    const auto chatter = d.topic("/chatter", "std_msgs/msg/String");
    d.write(chatter, 1012, say(12));
  }
  want.push_back("/chatter std_msgs/msg/String message 12");
  notes.clear();
  EXPECT_EQ(contents(read_log_container(dir, notes)), want);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("no metadata.yaml: read the bag's 4 files"));
  fs::remove_all(dir);
}

TEST(Rosbag2Storage, DamagedBagsAreReadAsFarAsTheyCanBeOrRefusedNamingWhere) {
  const std::string dir = test::temp_path("rosbag2_damaged");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string bag = dir + "/bag_0.db3";
  {
    test::Rosbag2SqliteWriter w(bag);
    const auto chatter = w.topic("/chatter", "std_msgs/msg/String");
    w.write(chatter, 10, ros2::string_message("kept"));
    w.write(chatter, 11, test::Rosbag2SqliteWriter::zstd(std::string(100, 'x')).substr(0, 12));
    w.write(7, 12, ros2::string_message("of no topic"));
    w.write(chatter, -5, ros2::string_message("before time"));
    w.write(chatter, 13, ros2::string_message("kept too"), true);
  }
  std::vector<std::string> notes;
  const McapFile f = read_log_container(bag, notes);
  EXPECT_EQ(f.messages.size(), 2u);
  EXPECT_EQ(f.report.skipped_records, 3u);
  std::string problems;
  for (const auto& p : f.report.problems) problems += p + "\n";
  std::cout << problems;
  EXPECT_THAT(problems, HasSubstr("table messages, id 2: data: zstd"));
  EXPECT_THAT(problems, HasSubstr("table messages, id 3: topic_id 7 is not in the topics table"));
  EXPECT_THAT(problems, HasSubstr("table messages, id 4: timestamp is negative"));

  auto refusal = [&](const std::string& path) {
    try {
      read_log_container(path, notes);
    } catch (const InputError& e) {
      std::cout << e.what() << "\n";
      return std::string(e.what());
    }
    return std::string("read");
  };
  {  // A SQLite database that is not a bag.
    sqlite3* db = nullptr;
    sqlite3_open((dir + "/other.db3").c_str(), &db);
    sqlite3_exec(db, "CREATE TABLE t(x INTEGER)", nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  EXPECT_THAT(refusal(dir + "/other.db3"),
              HasSubstr("other.db3: table topics: not a rosbag2 SQLite bag (no such table"));
  std::ofstream(dir + "/cut.db3", std::ios::binary) << slurp(bag).substr(0, 100);
  EXPECT_THAT(refusal(dir + "/cut.db3"), HasSubstr("cut.db3"));
  std::ofstream(dir + "/cut.db3.zstd", std::ios::binary)
      << test::Rosbag2SqliteWriter::zstd(slurp(bag)).substr(0, 40);
  EXPECT_THAT(refusal(dir + "/cut.db3.zstd"),
              HasSubstr("cut.db3.zstd: a zstd-compressed file that does not decompress"));
  std::ofstream(dir + "/metadata.yaml")
      << "rosbag2_bagfile_information:\n  relative_file_paths:\n    - bag_9.db3\n";
  EXPECT_THAT(refusal(dir), HasSubstr("metadata.yaml: rosbag2_bagfile_information: "
                                      "relative_file_paths: names bag_9.db3, which is not in"));
  std::ofstream(dir + "/metadata.yaml") << "rosbag2_bagfile_information: [1, 2\n";
  EXPECT_THAT(refusal(dir), HasSubstr("metadata.yaml: line"));
  const std::string empty = dir + "/empty";
  fs::create_directories(empty);
  EXPECT_THAT(refusal(empty), HasSubstr("not a ROS 2 bag"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lampnav::io
