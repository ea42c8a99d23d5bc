#include <zstd.h>

#include <algorithm>
#include <array>
#include <limits>

#include "bytes.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/io/mcap.hpp"
#include "mcap_records.hpp"

namespace lampnav::io {

using detail::ByteWriter;

std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  const auto* p = static_cast<const std::uint8_t*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ p[i]) & 0xff] ^ (crc >> 8);
  return ~crc;
}

namespace {

std::string record(std::uint8_t opcode, const std::string& body) {
  ByteWriter w;
  w.u8(opcode);
  w.u64(body.size());
  w.raw(body);
  return std::move(w.data());
}

struct ChunkIndexRec {
  std::uint64_t start_time, end_time, offset, length;
  std::map<std::uint16_t, std::uint64_t> index_offsets;
  std::uint64_t index_length;
  std::string compression;
  std::uint64_t compressed_size, uncompressed_size;
};

struct AttachmentIndexRec {
  std::uint64_t offset, length, log_time, create_time, data_size;
  std::string name, media_type;
};

}  // namespace

struct McapWriter::Impl {
  std::string path;
  McapWriterOptions opt;
  std::ofstream out;
  std::uint64_t pos = 0;
  bool closed = false;

  std::vector<std::string> schema_records, channel_records;
  std::uint16_t next_schema = 1, next_channel = 0;
  std::map<std::uint16_t, std::uint32_t> sequence;
  std::map<std::uint16_t, std::uint64_t> channel_counts;
  std::uint64_t message_count = 0;
  std::uint64_t start_time = std::numeric_limits<std::uint64_t>::max(), end_time = 0;

  std::string chunk;
  std::uint64_t chunk_start = std::numeric_limits<std::uint64_t>::max(), chunk_end = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_entries;
  std::vector<ChunkIndexRec> chunk_indexes;
  std::vector<AttachmentIndexRec> attachment_indexes;

  void emit(const std::string& bytes) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw Error(path + ": write error");
    pos += bytes.size();
  }

  void flush_chunk() {
    if (chunk.empty()) return;
    std::string payload = chunk;
    std::string compression;
    if (opt.compression == McapCompression::zstd) {
      std::string z(ZSTD_compressBound(chunk.size()), '\0');
      const std::size_t n =
          ZSTD_compress(z.data(), z.size(), chunk.data(), chunk.size(), opt.zstd_level);
      if (ZSTD_isError(n)) throw Error(path + ": zstd compression failed: " + ZSTD_getErrorName(n));
      z.resize(n);
      payload = std::move(z);
      compression = "zstd";
    }
    ByteWriter b;
    b.u64(chunk_start);
    b.u64(chunk_end);
    b.u64(chunk.size());
    b.u32(crc32(chunk.data(), chunk.size()));
    b.str(compression);
    b.bytes64(payload);
    ChunkIndexRec idx{chunk_start, chunk_end,      pos,         0, {}, 0,
                      compression, payload.size(), chunk.size()};
    emit(record(op::kChunk, b.data()));
    idx.length = pos - idx.offset;
    const std::uint64_t index_start = pos;
    for (const auto& [channel, entries] : chunk_entries) {
      ByteWriter m;
      m.u16(channel);
      ByteWriter list;
      for (const auto& [t, off] : entries) {
        list.u64(t);
        list.u64(off);
      }
      m.str(list.data());
      idx.index_offsets[channel] = pos;
      emit(record(op::kMessageIndex, m.data()));
    }
    idx.index_length = pos - index_start;
    chunk_indexes.push_back(std::move(idx));
    chunk.clear();
    chunk_entries.clear();
    chunk_start = std::numeric_limits<std::uint64_t>::max();
    chunk_end = 0;
  }

  void finish() {
    flush_chunk();
    ByteWriter data_end;
    data_end.u32(0);  // data section CRC not computed (allowed: zero means "not available")
    emit(record(op::kDataEnd, data_end.data()));

    std::uint64_t summary_start = 0, summary_offset_start = 0;
    std::string summary;
    std::vector<std::array<std::uint64_t, 3>> groups;  // opcode, start, length
    if (opt.summary) {
      summary_start = pos;
      auto group = [&](std::uint8_t opcode, const std::vector<std::string>& records) {
        if (records.empty()) return;
        const std::uint64_t start = summary_start + summary.size();
        for (const auto& r : records) summary += r;
        groups.push_back({opcode, start, summary_start + summary.size() - start});
      };
      group(op::kSchema, schema_records);
      group(op::kChannel, channel_records);
      ByteWriter st;
      st.u64(message_count);
      st.u16(static_cast<std::uint16_t>(schema_records.size()));
      st.u32(static_cast<std::uint32_t>(channel_records.size()));
      st.u32(static_cast<std::uint32_t>(attachment_indexes.size()));
      st.u32(0);  // metadata records
      st.u32(static_cast<std::uint32_t>(chunk_indexes.size()));
      st.u64(message_count ? start_time : 0);
      st.u64(message_count ? end_time : 0);
      ByteWriter counts;
      for (const auto& [ch, n] : channel_counts) {
        counts.u16(ch);
        counts.u64(n);
      }
      st.str(counts.data());
      group(op::kStatistics, {record(op::kStatistics, st.data())});
      std::vector<std::string> ci;
      for (const auto& c : chunk_indexes) {
        ByteWriter b;
        b.u64(c.start_time);
        b.u64(c.end_time);
        b.u64(c.offset);
        b.u64(c.length);
        ByteWriter offs;
        for (const auto& [ch, off] : c.index_offsets) {
          offs.u16(ch);
          offs.u64(off);
        }
        b.str(offs.data());
        b.u64(c.index_length);
        b.str(c.compression);
        b.u64(c.compressed_size);
        b.u64(c.uncompressed_size);
        ci.push_back(record(op::kChunkIndex, b.data()));
      }
      group(op::kChunkIndex, ci);
      std::vector<std::string> ai;
      for (const auto& a : attachment_indexes) {
        ByteWriter b;
        b.u64(a.offset);
        b.u64(a.length);
        b.u64(a.log_time);
        b.u64(a.create_time);
        b.u64(a.data_size);
        b.str(a.name);
        b.str(a.media_type);
        ai.push_back(record(op::kAttachmentIndex, b.data()));
      }
      group(op::kAttachmentIndex, ai);
      summary_offset_start = summary_start + summary.size();
      for (const auto& g : groups) {
        ByteWriter b;
        b.u8(static_cast<std::uint8_t>(g[0]));
        b.u64(g[1]);
        b.u64(g[2]);
        summary += record(op::kSummaryOffset, b.data());
      }
    }
    // The summary CRC covers the summary and summary offset sections and the footer record up to,
    // and including, summary_offset_start (opcode, content length 20, the two offsets).
    ByteWriter footer_head;
    footer_head.u8(op::kFooter);
    footer_head.u64(20);
    footer_head.u64(summary_start);
    footer_head.u64(summary_offset_start);
    const std::string covered = summary + footer_head.data();
    const std::uint32_t summary_crc = opt.summary ? crc32(covered.data(), covered.size()) : 0;
    ByteWriter full;
    full.u64(summary_start);
    full.u64(summary_offset_start);
    full.u32(summary_crc);
    emit(summary);
    emit(record(op::kFooter, full.data()));
    emit(std::string(op::kMagic, 8));
    out.flush();
    if (!out) throw Error(path + ": write error");
  }
};

McapWriter::McapWriter(const std::string& path, McapWriterOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->opt = std::move(options);
  impl_->out.open(path, std::ios::binary | std::ios::trunc);
  if (!impl_->out) throw InputError({path, "", ""}, "cannot open the file for writing");
  impl_->emit(std::string(op::kMagic, 8));
  ByteWriter h;
  h.str(impl_->opt.profile);
  h.str(impl_->opt.library);
  impl_->emit(record(op::kHeader, h.data()));
}

McapWriter::~McapWriter() {
  if (impl_ && !impl_->closed) {
    try {
      close();
    } catch (...) {
    }
  }
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                     const std::string& data) {
  ByteWriter b;
  const std::uint16_t id = impl_->next_schema++;
  b.u16(id);
  b.str(name);
  b.str(encoding);
  b.str(data);  // schema data: uint32 length + bytes, the same layout as a string
  std::string r = record(op::kSchema, b.data());
  impl_->emit(r);
  impl_->schema_records.push_back(std::move(r));
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  ByteWriter b;
  const std::uint16_t id = impl_->next_channel++;
  b.u16(id);
  b.u16(schema_id);
  b.str(topic);
  b.str(message_encoding);
  b.string_map(metadata);
  std::string r = record(op::kChannel, b.data());
  impl_->emit(r);
  impl_->channel_records.push_back(std::move(r));
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                       const std::string& data) {
  Impl& m = *impl_;
  if (channel_id >= m.next_channel)
    throw Error(m.path + ": message on unknown channel " + std::to_string(channel_id));
  ByteWriter b;
  b.u16(channel_id);
  b.u32(m.sequence[channel_id]++);
  b.u64(log_time);
  b.u64(publish_time);
  b.raw(data);
  const std::string r = record(op::kMessage, b.data());
  ++m.message_count;
  ++m.channel_counts[channel_id];
  m.start_time = std::min(m.start_time, log_time);
  m.end_time = std::max(m.end_time, log_time);
  if (!m.opt.chunked) {
    m.emit(r);
    return;
  }
  m.chunk_entries[channel_id].emplace_back(log_time, m.chunk.size());
  m.chunk += r;
  m.chunk_start = std::min(m.chunk_start, log_time);
  m.chunk_end = std::max(m.chunk_end, log_time);
  if (m.chunk.size() >= m.opt.chunk_size) m.flush_chunk();
}

void McapWriter::attach(const McapAttachment& a) {
  ByteWriter b;
  b.u64(a.log_time);
  b.u64(a.create_time);
  b.str(a.name);
  b.str(a.media_type);
  b.bytes64(a.data);
  b.u32(crc32(b.data().data(), b.size()));
  const std::uint64_t offset = impl_->pos;
  impl_->emit(record(op::kAttachment, b.data()));
  impl_->attachment_indexes.push_back({offset, impl_->pos - offset, a.log_time, a.create_time,
                                       a.data.size(), a.name, a.media_type});
}

void McapWriter::close() {
  if (impl_->closed) return;
  impl_->closed = true;
  impl_->finish();
  impl_->out.close();
}

}  // namespace lampnav::io
