#pragma once
// A small, clean MCAP (major version 0) writer and reader, written from the public MCAP format
// specification. The writer produces indexed files (chunks, message indexes, summary with schema,
// channel, statistics, chunk-index and attachment-index groups, summary offsets) with optional
// zstd chunk compression. The reader reads those, unchunked and unindexed files, and files cut off
// mid-write: every complete message before the cut is recovered and the cut is reported.

#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace lampnav::io {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;  // "jsonschema"
  std::string data;
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  // "json"
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns, when the data became available (mission-log.md)
  std::uint64_t publish_time = 0;  // ns
  std::string data;
};

struct McapAttachment {
  std::uint64_t log_time = 0, create_time = 0;
  std::string name, media_type, data;
};

enum class McapCompression { none, zstd };

struct McapWriterOptions {
  std::string profile;  // "" for a profile-free file
  std::string library = "lampnav 0.1.0";
  McapCompression compression = McapCompression::zstd;
  bool chunked = true;                  // false writes messages straight into the data section
  std::size_t chunk_size = 512 * 1024;  // bytes of records buffered before a chunk is written
  bool summary = true;                  // false leaves out the summary (an unindexed file)
  int zstd_level = 1;  // the fastest; 3 saves 5 % on a log of JPEG frames, 9 saves 9 % (make bench)
};

class McapWriter {
 public:
  // Creates or truncates `path`; throws lampnav::InputError naming it when it cannot be opened.
  McapWriter(const std::string& path, McapWriterOptions options = {});
  ~McapWriter();  // closes if close() was not called, swallowing errors
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::string& data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic,
                            const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});
  // Messages may come in any log_time order; each channel numbers its messages from 0.
  void write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
             const std::string& data);
  void attach(const McapAttachment& attachment);
  // Writes the last chunk, the summary and the footer. Throws lampnav::Error on a write error.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What a reader found besides the records.
struct McapReadReport {
  bool truncated = false;    // the file ends before its footer
  std::string truncation;    // where and how it ends
  bool has_summary = false;  // a summary section was found and read
  std::size_t chunks = 0;
  std::size_t skipped_records = 0;    // unknown opcodes, unreadable chunks (counted, see problems)
  std::vector<std::string> problems;  // what was skipped and why, in file order
};

struct McapFile {
  std::string profile, library;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::vector<McapMessage> messages;  // in file order
  std::vector<McapAttachment> attachments;
  McapReadReport report;

  const McapChannel* channel(std::uint16_t id) const;
  const McapChannel* channel(const std::string& topic) const;
  const McapSchema* schema(std::uint16_t id) const;
  const McapAttachment* attachment(const std::string& name) const;
};

// Reads a whole MCAP file. Throws lampnav::InputError naming the file and the byte offset for what
// cannot be read at all (missing file, bad magic, a malformed record before any message);
// damage after that is reported in `report` and everything readable is kept.
McapFile read_mcap(const std::string& path);
McapFile read_mcap_bytes(const std::string& bytes, const std::string& source);

// CRC-32 (ISO-HDLC, as zlib), as MCAP uses.
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace lampnav::io
