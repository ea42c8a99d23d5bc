#include "rosbag2_storage.hpp"

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>
#include <zstd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <tuple>

#include "lampnav/core/error.hpp"
#include "lampnav/internal/json_util.hpp"

namespace lampnav::io {

namespace fs = std::filesystem;

namespace {

// A message or file this large once decompressed is not a camera's or a bag's: refused before
// memory runs out (a zstd frame can claim any size).
constexpr std::uint64_t kMaxMessageBytes = 64ull << 20;
constexpr std::uint64_t kMaxFileBytes = 64ull << 30;
// A bag's messages compressed one by one give back at most this many times the bag's size, or
// 256 MiB (camera frames compress a few times; a run of zeros, thousands).
constexpr std::uint64_t kMaxMessageRatio = 64, kMinMessageBudget = 256ull << 20;

bool starts_with(const std::string& bytes, const char* magic, std::size_t n) {
  return bytes.size() >= n && std::equal(magic, magic + n, bytes.begin());
}
bool is_zstd(const std::string& b) { return starts_with(b, "\x28\xB5\x2F\xFD", 4); }
bool is_sqlite(const std::string& b) { return starts_with(b, "SQLite format 3\0", 16); }

// One or more zstd frames, decompressed; throws the reason as a string.
std::string unzstd(const std::string& in, std::uint64_t max_bytes) {
  std::unique_ptr<ZSTD_DStream, decltype(&ZSTD_freeDStream)> z(ZSTD_createDStream(),
                                                               ZSTD_freeDStream);
  if (!z) throw std::string("zstd: out of memory");
  ZSTD_initDStream(z.get());
  std::string out;
  ZSTD_inBuffer src{in.data(), in.size(), 0};
  for (;;) {
    if (out.size() > max_bytes)
      throw "decompresses to more than " + std::to_string(max_bytes >> 20) + " MiB";
    const std::size_t before = out.size(), chunk = ZSTD_DStreamOutSize();
    const std::size_t consumed = src.pos;
    out.resize(before + chunk);
    ZSTD_outBuffer dst{out.data() + before, chunk, 0};
    const std::size_t wants = ZSTD_decompressStream(z.get(), &dst, &src);
    out.resize(before + dst.pos);
    if (ZSTD_isError(wants)) throw std::string("zstd: ") + ZSTD_getErrorName(wants);
    if (wants == 0 && src.pos == src.size) return out;  // every frame whole
    // Input used up, the output not full, and the decoder wants more: the data was cut.
    if (src.pos == src.size && dst.pos < chunk) throw std::string("zstd: the data ends in a frame");
    if (dst.pos == 0 && src.pos == consumed) throw std::string("zstd: no progress");
  }
}

// The first bytes of a file, to tell its container.
std::string head(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, "", ""}, "cannot open the file for reading");
  std::string b(16, '\0');
  in.read(b.data(), 16);
  b.resize(static_cast<std::size_t>(in.gcount()));
  return b;
}

struct Connection {
  sqlite3* db = nullptr;
  ~Connection() { sqlite3_close(db); }
};

struct Statement {
  sqlite3_stmt* s = nullptr;
  ~Statement() { sqlite3_finalize(s); }
};

std::string text(sqlite3_stmt* s, int column) {
  const unsigned char* t = sqlite3_column_text(s, column);
  return t ? std::string(reinterpret_cast<const char*>(t),
                         static_cast<std::size_t>(sqlite3_column_bytes(s, column)))
           : std::string();
}

// The bag's tables as a McapFile. Throws InputError when the topics cannot be read; a message
// that cannot be is skipped and reported, as the MCAP reader does with damaged records.
McapFile from_sqlite(sqlite3* db, const std::string& source, std::uint64_t stored_bytes) {
  McapFile f;
  f.library = "rosbag2 sqlite3";
  auto fail = [&](const std::string& place, const std::string& what) {
    throw InputError({source, place, ""}, what);
  };
  Statement topics;
  if (sqlite3_prepare_v2(db, "SELECT id, name, type, serialization_format FROM topics", -1,
                         &topics.s, nullptr) != SQLITE_OK)
    fail("table topics", std::string("not a rosbag2 SQLite bag (") + sqlite3_errmsg(db) + ")");
  std::map<std::int64_t, std::uint16_t> channel_of;  // topics.id -> channel
  std::map<std::string, std::uint16_t> schema_of;    // type -> schema
  int rc;
  while ((rc = sqlite3_step(topics.s)) == SQLITE_ROW) {
    const std::int64_t id = sqlite3_column_int64(topics.s, 0);
    const std::string place = "table topics, id " + std::to_string(id);
    McapChannel ch;
    ch.topic = text(topics.s, 1);
    const std::string type = text(topics.s, 2);
    ch.message_encoding = text(topics.s, 3);
    if (ch.topic.empty() || type.empty()) fail(place, "a topic without a name or a type");
    if (channel_of.count(id)) fail(place, "two topics with one id");
    if (f.channels.size() >= 65535) fail(place, "more than 65535 topics");
    auto [it, added] = schema_of.emplace(type, static_cast<std::uint16_t>(f.schemas.size() + 1));
    if (added) f.schemas.push_back({it->second, type, "ros2msg", ""});
    ch.schema_id = it->second;
    ch.id = static_cast<std::uint16_t>(f.channels.size() + 1);
    channel_of[id] = ch.id;
    f.channels.push_back(std::move(ch));
  }
  if (rc != SQLITE_DONE) fail("table topics", sqlite3_errmsg(db));

  Statement messages;
  if (sqlite3_prepare_v2(
          db, "SELECT id, topic_id, timestamp, data FROM messages ORDER BY timestamp, id", -1,
          &messages.s, nullptr) != SQLITE_OK)
    fail("table messages", std::string("not a rosbag2 SQLite bag (") + sqlite3_errmsg(db) + ")");
  std::map<std::uint16_t, std::uint32_t> sequence;
  const std::uint64_t budget = std::max(
      kMinMessageBudget, kMaxMessageRatio * std::min<std::uint64_t>(stored_bytes, 1ull << 40));
  std::uint64_t unpacked = 0;
  auto skip = [&](const std::string& place, const std::string& what) {
    ++f.report.skipped_records;
    f.report.problems.push_back(source + ": " + place + ": " + what + " (skipped)");
  };
  while ((rc = sqlite3_step(messages.s)) == SQLITE_ROW) {
    const std::string place =
        "table messages, id " + std::to_string(sqlite3_column_int64(messages.s, 0));
    const auto ch = channel_of.find(sqlite3_column_int64(messages.s, 1));
    if (ch == channel_of.end()) {
      skip(place, "topic_id " + std::to_string(sqlite3_column_int64(messages.s, 1)) +
                      " is not in the topics table");
      continue;
    }
    const std::int64_t t = sqlite3_column_int64(messages.s, 2);
    if (t < 0) {
      skip(place, "timestamp is negative");
      continue;
    }
    McapMessage m;
    m.channel_id = ch->second;
    m.log_time = m.publish_time = static_cast<std::uint64_t>(t);
    m.sequence = sequence[ch->second]++;
    const void* blob = sqlite3_column_blob(messages.s, 3);
    m.data.assign(static_cast<const char*>(blob),
                  blob ? static_cast<std::size_t>(sqlite3_column_bytes(messages.s, 3)) : 0);
    if (is_zstd(m.data)) {  // --compression-mode message: a CDR message never starts so
      try {
        m.data = unzstd(m.data, kMaxMessageBytes);
      } catch (const std::string& why) {
        skip(place, "data: " + why);
        continue;
      }
      unpacked += m.data.size();
      if (unpacked > budget) {
        skip(place, "data: the bag's messages decompress to more than " +
                        std::to_string(kMaxMessageRatio) + " times its size");
        continue;
      }
    }
    f.messages.push_back(std::move(m));
  }
  if (rc != SQLITE_DONE) {
    if (f.messages.empty()) fail("table messages", sqlite3_errmsg(db));
    f.report.truncated = true;
    f.report.truncation = "table messages: " + std::string(sqlite3_errmsg(db)) + " after " +
                          std::to_string(f.messages.size()) + " messages";
    f.report.problems.push_back(source + ": " + f.report.truncation);
  }
  return f;
}

// sqlite3 reads a bag in place, as immutable (no file made beside it, none changed), unless
// the bag was left with a write-ahead log (recording stopped without closing it): then the log is
// read too, which may make a shared-memory file beside it, as rosbag2 itself does.
McapFile read_sqlite_file(const std::string& path) {
  std::error_code ec;
  const std::string wal = path + "-wal";
  const bool has_log = fs::exists(wal, ec) && fs::file_size(wal, ec) > 0 && !ec;
  std::string name = path;
  int flags = SQLITE_OPEN_READONLY;
  if (!has_log) {
    name = "file:";
    for (const char ch : fs::absolute(path).string()) {
      if (ch == '%' || ch == '?' || ch == '#') {
        static const char* hex = "0123456789ABCDEF";
        name += '%';
        name += hex[(ch >> 4) & 15];
        name += hex[ch & 15];
      } else {
        name += ch;
      }
    }
    name += "?immutable=1";
    flags |= SQLITE_OPEN_URI;
  }
  Connection c;
  if (sqlite3_open_v2(name.c_str(), &c.db, flags, nullptr) != SQLITE_OK)
    throw InputError({path, "", ""}, std::string("cannot open as SQLite: ") +
                                         (c.db ? sqlite3_errmsg(c.db) : "out of memory"));
  const std::uintmax_t size = fs::file_size(path, ec);
  return from_sqlite(c.db, path, ec ? 0 : size);
}

// A number at the end of a file's stem ("bag_12.db3" -> 12), to order a split bag's files.
std::tuple<std::string, long long, std::string> split_order(const fs::path& p) {
  std::string stem = p.filename().string();
  stem = stem.substr(0, stem.find('.'));
  std::size_t k = stem.size();
  while (k > 0 && std::isdigit(static_cast<unsigned char>(stem[k - 1]))) --k;
  const long long n = k < stem.size() && stem.size() - k < 18 ? std::stoll(stem.substr(k)) : -1;
  return {stem.substr(0, k), n, p.filename().string()};
}

McapFile read_file(const std::string& path);

// Appends `part` (one file of a split bag) to `into`, its schemas and channels matched by name.
void append(McapFile& into, McapFile part, const std::string& source) {
  std::map<std::uint16_t, std::uint16_t> schema_id, channel_id;
  for (const auto& s : part.schemas) {
    auto same = std::find_if(into.schemas.begin(), into.schemas.end(), [&](const McapSchema& k) {
      return k.name == s.name && k.encoding == s.encoding;
    });
    if (same == into.schemas.end()) {
      McapSchema added = s;
      added.id = static_cast<std::uint16_t>(into.schemas.size() + 1);
      into.schemas.push_back(added);
      same = into.schemas.end() - 1;
    }
    schema_id[s.id] = same->id;
  }
  for (const auto& c : part.channels) {
    const std::uint16_t schema = c.schema_id == 0 ? 0 : schema_id[c.schema_id];
    auto same = std::find_if(into.channels.begin(), into.channels.end(), [&](const McapChannel& k) {
      return k.topic == c.topic && k.message_encoding == c.message_encoding &&
             k.schema_id == schema;
    });
    if (same == into.channels.end()) {
      if (into.channels.size() >= 65535)
        throw InputError({source, "", ""}, "the bag's files hold more than 65535 topics");
      McapChannel added = c;
      added.id = static_cast<std::uint16_t>(into.channels.size() + 1);
      added.schema_id = schema;
      into.channels.push_back(added);
      same = into.channels.end() - 1;
    }
    channel_id[c.id] = same->id;
  }
  for (auto& m : part.messages) {
    const auto it = channel_id.find(m.channel_id);
    if (it == channel_id.end()) continue;  // a record of no channel: dropped as the reader does
    m.channel_id = it->second;
    into.messages.push_back(std::move(m));
  }
  for (auto& a : part.attachments) into.attachments.push_back(std::move(a));
  into.report.truncated = into.report.truncated || part.report.truncated;
  if (into.report.truncation.empty()) into.report.truncation = part.report.truncation;
  into.report.has_summary = into.report.has_summary || part.report.has_summary;
  into.report.chunks += part.report.chunks;
  into.report.skipped_records += part.report.skipped_records;
  for (auto& p : part.report.problems) into.report.problems.push_back(std::move(p));
  if (into.library.empty()) into.library = part.library;
  if (into.profile.empty()) into.profile = part.profile;
}

McapFile read_directory(const std::string& dir, std::vector<std::string>& notes) {
  const fs::path metadata = fs::path(dir) / "metadata.yaml";
  std::vector<fs::path> files;
  if (fs::exists(metadata)) {
    const std::string where = metadata.string();
    try {
      const YAML::Node info = YAML::LoadFile(where)["rosbag2_bagfile_information"];
      if (!info || !info.IsMap())
        throw InputError({where, "", "rosbag2_bagfile_information"},
                         "missing: not a rosbag2 bag's metadata");
      const YAML::Node paths = info["relative_file_paths"];
      if (!paths || !paths.IsSequence() || paths.size() == 0)
        throw InputError({where, "rosbag2_bagfile_information", "relative_file_paths"},
                         "missing or empty: the bag names no file");
      for (const auto& p : paths) {
        if (!p.IsScalar())
          throw InputError({where, "rosbag2_bagfile_information", "relative_file_paths"},
                           "holds something other than a file name");
        const fs::path file = fs::path(dir) / p.as<std::string>();
        if (!fs::exists(file))
          throw InputError({where, "rosbag2_bagfile_information", "relative_file_paths"},
                           "names " + p.as<std::string>() + ", which is not in " + dir);
        files.push_back(file);
      }
      const std::string storage =
          info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "";
      notes.push_back("rosbag2 bag (" +
                      (storage.empty() ? std::string("storage not named") : storage + " storage") +
                      "), " + std::to_string(files.size()) + " file" +
                      (files.size() == 1 ? "" : "s") + " as its metadata.yaml lists them");
    } catch (const YAML::Exception& e) {
      throw InputError({where, "line " + std::to_string(e.mark.line + 1), ""},
                       "not readable as YAML: " + e.msg);
    }
  } else {
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      auto ends = [&](const std::string& s) {
        return name.size() >= s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
      };
      if (e.is_regular_file() && (ends(".db3") || ends(".mcap") || ends(".zstd")))
        files.push_back(e.path());
    }
    if (files.empty())
      throw InputError({dir, "", ""},
                       "a directory with no metadata.yaml and no .db3, .mcap or .zstd file: not "
                       "a ROS 2 bag");
    std::sort(files.begin(), files.end(),
              [](const fs::path& a, const fs::path& b) { return split_order(a) < split_order(b); });
    notes.push_back("no metadata.yaml: read the bag's " + std::to_string(files.size()) + " file" +
                    (files.size() == 1 ? "" : "s") + " in the order of their numbers");
  }
  McapFile all;
  for (const auto& f : files) append(all, read_file(f.string()), dir);
  std::stable_sort(
      all.messages.begin(), all.messages.end(),
      [](const McapMessage& a, const McapMessage& b) { return a.log_time < b.log_time; });
  return all;
}

McapFile read_file(const std::string& path) {
  const std::string magic = head(path);
  if (is_sqlite(magic)) return read_sqlite_file(path);
  if (is_zstd(magic)) {  // --compression-mode file
    std::string bytes;
    try {
      bytes = unzstd(json::read_file(path), kMaxFileBytes);
    } catch (const std::string& why) {
      throw InputError({path, "", ""}, "a zstd-compressed file that does not decompress: " + why);
    }
    return read_log_bytes(bytes, path);
  }
  return read_mcap(path);
}

}  // namespace

McapFile read_sqlite_bag_bytes(const std::string& bytes, const std::string& source) {
  if (!is_sqlite(bytes)) throw InputError({source, "", ""}, "not a SQLite file");
  // The bytes are a file as written; a database left in write-ahead-log mode is read as a plain
  // one (the log itself is another file, not in these bytes).
  std::string copy = bytes;
  if (copy.size() > 19 && copy[18] == 2 && copy[19] == 2) copy[18] = copy[19] = 1;
  Connection c;
  if (sqlite3_open_v2(":memory:", &c.db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK)
    throw InputError({source, "", ""}, "SQLite: out of memory");
  if (sqlite3_deserialize(c.db, "main", reinterpret_cast<unsigned char*>(copy.data()),
                          static_cast<sqlite3_int64>(copy.size()),
                          static_cast<sqlite3_int64>(copy.size()),
                          SQLITE_DESERIALIZE_READONLY) != SQLITE_OK)
    throw InputError({source, "", ""},
                     std::string("cannot read as SQLite: ") + sqlite3_errmsg(c.db));
  return from_sqlite(c.db, source, bytes.size());
}

McapFile read_log_bytes(const std::string& bytes, const std::string& source) {
  if (is_sqlite(bytes)) return read_sqlite_bag_bytes(bytes, source);
  return read_mcap_bytes(bytes, source);
}

McapFile read_log_container(const std::string& path, std::vector<std::string>& notes) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return read_directory(path, notes);
  return read_file(path);
}

}  // namespace lampnav::io
