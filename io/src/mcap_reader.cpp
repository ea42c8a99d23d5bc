#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "bytes.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/io/mcap.hpp"
#include "mcap_records.hpp"

namespace lampnav::io {

using detail::ByteReader;
using detail::Malformed;

const McapChannel* McapFile::channel(std::uint16_t id) const {
  for (const auto& c : channels) {
    if (c.id == id) return &c;
  }
  return nullptr;
}
const McapChannel* McapFile::channel(const std::string& topic) const {
  for (const auto& c : channels) {
    if (c.topic == topic) return &c;
  }
  return nullptr;
}
const McapSchema* McapFile::schema(std::uint16_t id) const {
  for (const auto& s : schemas) {
    if (s.id == id) return &s;
  }
  return nullptr;
}
const McapAttachment* McapFile::attachment(const std::string& name) const {
  for (const auto& a : attachments) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

namespace {

const char* record_name(std::uint8_t opcode) {
  switch (opcode) {
    case op::kHeader:
      return "Header";
    case op::kFooter:
      return "Footer";
    case op::kSchema:
      return "Schema";
    case op::kChannel:
      return "Channel";
    case op::kMessage:
      return "Message";
    case op::kChunk:
      return "Chunk";
    case op::kMessageIndex:
      return "Message Index";
    case op::kChunkIndex:
      return "Chunk Index";
    case op::kAttachment:
      return "Attachment";
    case op::kAttachmentIndex:
      return "Attachment Index";
    case op::kStatistics:
      return "Statistics";
    case op::kMetadata:
      return "Metadata";
    case op::kMetadataIndex:
      return "Metadata Index";
    case op::kSummaryOffset:
      return "Summary Offset";
    case op::kDataEnd:
      return "Data End";
    default:
      return "unknown";
  }
}

// A record's opcode and content length, read from 9 bytes at `p` (the caller checks they exist).
std::pair<std::uint8_t, std::uint64_t> record_header(const char* p) {
  detail::ByteReader r(p, 9);
  const std::uint8_t opcode = r.u8();
  return {opcode, r.u64()};
}

class Parser {
 public:
  Parser(const std::string& bytes, std::string source) : b_(bytes), source_(std::move(source)) {}

  McapFile parse() {
    if (b_.size() < 8 || std::memcmp(b_.data(), op::kMagic, 8) != 0) {
      fail(0, b_.size() < 8 ? "not an MCAP file: shorter than its magic bytes"
                            : "not an MCAP file: bad magic bytes (expected 0x89 MCAP0 \\r\\n)");
    }
    std::size_t pos = 8;
    bool footer = false;
    while (pos < b_.size()) {
      if (b_.size() - pos < 9) {
        truncated(pos, "inside a record's opcode and length");
        break;
      }
      const auto [opcode, len] = record_header(b_.data() + pos);
      const std::size_t body = pos + 9;
      if (len > b_.size() - body) {
        truncated(pos, std::string("inside a ") + record_name(opcode) + " record of " +
                           std::to_string(len) + " bytes");
        if (opcode == op::kChunk) salvage_chunk(pos, b_.size() - body);
        break;
      }
      if (opcode == op::kFooter) {
        footer = true;
        pos = body + len;
        break;
      }
      handle(opcode, pos, ByteReader(b_.data() + body, static_cast<std::size_t>(len)), true);
      pos = body + len;
    }
    if (!footer && !file_.report.truncated) {
      file_.report.truncated = true;
      file_.report.truncation = "the file ends at byte " + std::to_string(b_.size()) +
                                ", after a complete record but before the footer";
    }
    if (footer) {
      if (b_.size() - pos < 8) {
        truncated(pos, "inside the closing magic bytes");
      } else if (std::memcmp(b_.data() + pos, op::kMagic, 8) != 0) {
        problem(pos, "no magic bytes after the footer");
      }
      file_.report.has_summary = saw_summary_;
    }
    return std::move(file_);
  }

 private:
  [[noreturn]] void fail(std::size_t offset, const std::string& message) const {
    throw InputError({source_, "byte " + std::to_string(offset), ""}, message);
  }
  void problem(std::size_t offset, const std::string& message) {
    file_.report.problems.push_back("byte " + std::to_string(offset) + ": " + message);
  }
  void truncated(std::size_t offset, const std::string& what) {
    file_.report.truncated = true;
    file_.report.truncation = "the file ends at byte " + std::to_string(b_.size()) + ", " + what +
                              " starting at byte " + std::to_string(offset);
  }

  // A malformed record: fatal before any message (the file is not what it claims), else skipped.
  void malformed(std::uint8_t opcode, std::size_t offset, const std::string& why) {
    const std::string msg = std::string("malformed ") + record_name(opcode) + " record: " + why;
    if (file_.messages.empty() && file_.channels.empty()) fail(offset, msg);
    ++file_.report.skipped_records;
    problem(offset, msg + " (skipped)");
  }

  void handle(std::uint8_t opcode, std::size_t offset, ByteReader r, bool top_level) {
    try {
      switch (opcode) {
        case op::kHeader:
          file_.profile = r.str();
          file_.library = r.str();
          break;
        case op::kSchema: {
          McapSchema s;
          s.id = r.u16();
          s.name = r.str();
          s.encoding = r.str();
          s.data = r.str();
          if (s.id == 0) throw Malformed("schema id 0 is reserved");
          if (!file_.schema(s.id)) file_.schemas.push_back(std::move(s));
          if (summary_) saw_summary_ = true;
          break;
        }
        case op::kChannel: {
          McapChannel c;
          c.id = r.u16();
          c.schema_id = r.u16();
          c.topic = r.str();
          c.message_encoding = r.str();
          c.metadata = r.string_map();
          if (!file_.channel(c.id)) file_.channels.push_back(std::move(c));
          if (summary_) saw_summary_ = true;
          break;
        }
        case op::kMessage: {
          McapMessage m;
          m.channel_id = r.u16();
          m.sequence = r.u32();
          m.log_time = r.u64();
          m.publish_time = r.u64();
          m.data = r.rest();
          if (!file_.channel(m.channel_id)) {
            ++file_.report.skipped_records;
            problem(offset, "message on channel " + std::to_string(m.channel_id) +
                                " that no Channel record defines (skipped)");
            break;
          }
          file_.messages.push_back(std::move(m));
          break;
        }
        case op::kChunk:
          if (!top_level) throw Malformed("a chunk inside a chunk");
          read_chunk(offset, r);
          break;
        case op::kAttachment: {
          const std::size_t start = r.offset();
          McapAttachment a;
          a.log_time = r.u64();
          a.create_time = r.u64();
          a.name = r.str();
          a.media_type = r.str();
          a.data = r.bytes64();
          const std::size_t covered = r.offset() - start;
          const std::uint32_t crc = r.u32();
          const std::uint32_t actual = crc32(b_.data() + offset + 9 + start, covered);
          if (crc != 0 && crc != actual) {
            ++file_.report.skipped_records;
            problem(offset, "attachment '" + a.name + "' fails its CRC check (skipped)");
            break;
          }
          file_.attachments.push_back(std::move(a));
          break;
        }
        case op::kDataEnd:
          summary_ = true;  // what follows is the summary section
          break;
        case op::kMessageIndex:
        case op::kChunkIndex:
        case op::kAttachmentIndex:
        case op::kStatistics:
        case op::kMetadata:
        case op::kMetadataIndex:
        case op::kSummaryOffset:
          if (summary_) saw_summary_ = true;
          break;  // indexes serve seeking readers; a full read needs none of them
        default:
          // Unknown opcodes are skipped, as the specification asks of readers.
          ++file_.report.skipped_records;
          problem(offset, "unknown record opcode 0x" + hex(opcode) + " (skipped)");
          break;
      }
    } catch (const Malformed& e) {
      malformed(opcode, offset, e.what());
    }
  }

  static std::string hex(std::uint8_t v) {
    const char* d = "0123456789abcdef";
    return {d[v >> 4], d[v & 15]};
  }

  // Reads the records inside a chunk's (decompressed) content; stops at an incomplete record.
  void read_records(const std::string& records, std::size_t chunk_offset) {
    std::size_t p = 0;
    while (p < records.size()) {
      if (records.size() - p < 9) break;
      const auto [opcode, len] = record_header(records.data() + p);
      if (len > records.size() - p - 9) {
        problem(chunk_offset,
                "a record inside the chunk runs past the chunk's end (rest of the chunk skipped)");
        ++file_.report.skipped_records;
        return;
      }
      handle(opcode, chunk_offset,
             ByteReader(records.data() + p + 9, static_cast<std::size_t>(len)), false);
      p += 9 + len;
    }
  }

  void read_chunk(std::size_t offset, ByteReader& r) {
    ++file_.report.chunks;
    r.u64();  // message_start_time
    r.u64();  // message_end_time
    const std::uint64_t uncompressed_size = r.u64();
    const std::uint32_t uncompressed_crc = r.u32();
    const std::string compression = r.str();
    const std::string payload = r.bytes64();
    std::string records;
    if (compression.empty()) {
      records = payload;
    } else if (compression == "zstd") {
      // Trust the size only when the zstd frame itself says the same: a damaged field must not
      // make the reader allocate gigabytes.
      const unsigned long long frame = ZSTD_getFrameContentSize(payload.data(), payload.size());
      if (frame == ZSTD_CONTENTSIZE_ERROR || frame == ZSTD_CONTENTSIZE_UNKNOWN ||
          frame != uncompressed_size || uncompressed_size > (std::uint64_t{1} << 32)) {
        ++file_.report.skipped_records;
        problem(offset, "chunk's uncompressed size does not match its zstd frame (skipped)");
        return;
      }
      records.resize(static_cast<std::size_t>(uncompressed_size));
      const std::size_t n =
          ZSTD_decompress(records.data(), records.size(), payload.data(), payload.size());
      if (ZSTD_isError(n) || n != uncompressed_size) {
        ++file_.report.skipped_records;
        problem(offset, std::string("chunk does not decompress: ") +
                            (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "size differs") +
                            " (skipped)");
        return;
      }
    } else {
      ++file_.report.skipped_records;
      problem(offset, "chunk compression '" + compression + "' is not supported (skipped)");
      return;
    }
    if (uncompressed_crc != 0 && crc32(records.data(), records.size()) != uncompressed_crc) {
      ++file_.report.skipped_records;
      problem(offset, "chunk fails its CRC check (skipped)");
      return;
    }
    read_records(records, offset);
  }

  // A chunk cut off by the end of the file: an uncompressed one still holds complete records.
  void salvage_chunk(std::size_t offset, std::size_t available) {
    try {
      ByteReader r(b_.data() + offset + 9, available);
      r.u64();
      r.u64();
      r.u64();
      r.u32();
      const std::string compression = r.str();
      const std::uint64_t len = r.u64();
      (void)len;
      if (!compression.empty()) return;  // a cut compressed stream is not recovered
      read_records(r.rest(), offset);
    } catch (const Malformed&) {
      // The cut fell inside the chunk's own fields: nothing to salvage.
    }
  }

  const std::string& b_;
  std::string source_;
  McapFile file_;
  bool summary_ = false;
  bool saw_summary_ = false;
};

}  // namespace

McapFile read_mcap_bytes(const std::string& bytes, const std::string& source) {
  return Parser(bytes, source).parse();
}

McapFile read_mcap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, "", ""}, "cannot open the file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return read_mcap_bytes(ss.str(), path);
}

}  // namespace lampnav::io
