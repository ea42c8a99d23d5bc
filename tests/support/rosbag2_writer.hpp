#pragma once
// A rosbag2 sqlite3 bag file written as `ros2 bag record -s sqlite3` lays it out (the tables of
// rosbag2 from Jazzy on: topics with their QoS and type hash, messages, schema, metadata), for
// tests that need bags rosbag2 would write: split, compressed message by message with zstd, or
// damaged. Written with SQLite itself.

#include <sqlite3.h>
#include <zstd.h>

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

#include "lampnav/io/mcap.hpp"

namespace lampnav::test {

class Rosbag2SqliteWriter {
 public:
  explicit Rosbag2SqliteWriter(const std::string& path) {
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) fail("open");
    exec(
        "PRAGMA journal_mode=WAL;"
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
        "INSERT INTO schema VALUES (4, 'jazzy');"
        "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
        "metadata TEXT NOT NULL);"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
        "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL, "
        "type_description_hash TEXT NOT NULL DEFAULT '');"
        "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, "
        "encoding TEXT NOT NULL, encoded_message_definition TEXT NOT NULL, "
        "type_description_hash TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
        "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "BEGIN;");
    if (sqlite3_prepare_v2(db_, "INSERT INTO messages(topic_id, timestamp, data) VALUES (?,?,?)",
                           -1, &insert_, nullptr) != SQLITE_OK)
      fail("prepare");
  }
  ~Rosbag2SqliteWriter() {
    sqlite3_finalize(insert_);
    sqlite3_exec(db_, "COMMIT; PRAGMA wal_checkpoint(TRUNCATE);", nullptr, nullptr, nullptr);
    sqlite3_close(db_);
  }
  Rosbag2SqliteWriter(const Rosbag2SqliteWriter&) = delete;
  Rosbag2SqliteWriter& operator=(const Rosbag2SqliteWriter&) = delete;

  // A topic; its id in the bag.
  std::int64_t topic(const std::string& name, const std::string& type,
                     const std::string& format = "cdr") {
    const std::int64_t id = ++topics_;
    exec("INSERT INTO topics(id, name, type, serialization_format, offered_qos_profiles) VALUES (" +
         std::to_string(id) + ", '" + name + "', '" + type + "', '" + format + "', '')");
    return id;
  }
  // A message of `topic` received at `t_ns`; `compress`: as `--compression-mode message` stores
  // it (one zstd frame).
  void write(std::int64_t topic, std::int64_t t_ns, const std::string& data,
             bool compress = false) {
    const std::string stored = compress ? zstd(data) : data;
    sqlite3_reset(insert_);
    sqlite3_bind_int64(insert_, 1, topic);
    sqlite3_bind_int64(insert_, 2, t_ns);
    sqlite3_bind_blob(insert_, 3, stored.data(), static_cast<int>(stored.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(insert_) != SQLITE_DONE) fail("insert");
  }
  // Messages [begin, end) of an MCAP bag, every one of its topics first; `compress(message)`
  // says which to store compressed.
  template <class Compress>
  void copy(const io::McapFile& bag, std::size_t begin, std::size_t end, Compress compress) {
    std::map<std::uint16_t, std::int64_t> topic_of;
    for (const auto& ch : bag.channels)
      topic_of[ch.id] = topic(ch.topic, bag.schema(ch.schema_id)->name, ch.message_encoding);
    for (std::size_t k = begin; k < end && k < bag.messages.size(); ++k) {
      const io::McapMessage& m = bag.messages[k];
      write(topic_of[m.channel_id], static_cast<std::int64_t>(m.log_time), m.data, compress(m));
    }
  }
  void exec(const std::string& sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) fail(sql);
  }

  static std::string zstd(const std::string& data) {
    std::string out(ZSTD_compressBound(data.size()), '\0');
    const std::size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 1);
    if (ZSTD_isError(n)) throw std::runtime_error("zstd");
    out.resize(n);
    return out;
  }

 private:
  void fail(const std::string& what) {
    throw std::runtime_error("rosbag2 writer: " + what + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_ = nullptr;
  std::int64_t topics_ = 0;
};

}  // namespace lampnav::test
