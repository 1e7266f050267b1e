#include "agnocast/mcap/records.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>

namespace agnocast::mcap {
namespace {

// Builds one record: reserves the prefix, appends fields, patches the length.
class RecordWriter {
 public:
  RecordWriter(std::vector<std::uint8_t>& out, Opcode opcode) : out_(out), start_(out.size()) {
    out_.push_back(static_cast<std::uint8_t>(opcode));
    u64(0);
  }
  ~RecordWriter() {
    const std::uint64_t length = out_.size() - start_ - record_prefix_size;
    std::memcpy(out_.data() + start_ + 1, &length, sizeof length);
  }
  RecordWriter(const RecordWriter&) = delete;
  RecordWriter& operator=(const RecordWriter&) = delete;

  void u8(std::uint8_t value) { out_.push_back(value); }
  void u16(std::uint16_t value) { put(&value, sizeof value); }
  void u32(std::uint32_t value) { put(&value, sizeof value); }
  void u64(std::uint64_t value) { put(&value, sizeof value); }
  void string(std::string_view text) {
    u32(length32(text.size()));
    put(text.data(), text.size());
  }
  void bytes32(std::span<const std::uint8_t> bytes) {
    u32(length32(bytes.size()));
    put(bytes.data(), bytes.size());
  }
  void bytes64(std::span<const std::uint8_t> bytes) {
    u64(bytes.size());
    put(bytes.data(), bytes.size());
  }
  void raw(std::span<const std::uint8_t> bytes) { put(bytes.data(), bytes.size()); }
  void string_map(const StringMap& map) {
    const std::size_t at = begin_length();
    for (const auto& [key, value] : map) {
      string(key);
      string(value);
    }
    end_length(at);
  }
  void u16_u64_map(const std::map<std::uint16_t, std::uint64_t>& map) {
    const std::size_t at = begin_length();
    for (const auto& [key, value] : map) {
      u16(key);
      u64(value);
    }
    end_length(at);
  }
  void pairs(const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries) {
    const std::size_t at = begin_length();
    for (const auto& [first, second] : entries) {
      u64(first);
      u64(second);
    }
    end_length(at);
  }

 private:
  static std::uint32_t length32(std::size_t size) {
    if (size > std::numeric_limits<std::uint32_t>::max()) {
      throw FormatError("mcap: a field longer than 4 GiB cannot be written");
    }
    return static_cast<std::uint32_t>(size);
  }
  std::size_t begin_length() {
    const std::size_t at = out_.size();
    u32(0);
    return at;
  }
  void end_length(std::size_t at) {
    const std::uint32_t length = length32(out_.size() - at - sizeof(std::uint32_t));
    std::memcpy(out_.data() + at, &length, sizeof length);
  }
  [[gnu::noinline]] void put(const void* bytes, std::size_t size) {
    if (size == 0) return;
    const std::size_t at = out_.size();
    out_.resize(at + size);
    std::memcpy(out_.data() + at, bytes, size);
  }

  std::vector<std::uint8_t>& out_;
  std::size_t start_;
};

// Reads fields of one record's content; running past its end is a FormatError.
class Cursor {
 public:
  Cursor(std::span<const std::uint8_t> content, const char* record)
      : in_(content), record_(record) {}

  std::uint8_t u8() { return *take(1); }
  std::uint16_t u16() { return get<std::uint16_t>(); }
  std::uint32_t u32() { return get<std::uint32_t>(); }
  std::uint64_t u64() { return get<std::uint64_t>(); }
  std::string string() {
    const std::uint32_t length = u32();
    const auto* bytes = take(length);
    return std::string(reinterpret_cast<const char*>(bytes), length);
  }
  std::span<const std::uint8_t> bytes32() {
    const std::uint32_t length = u32();
    return {take(length), length};
  }
  std::span<const std::uint8_t> bytes64() {
    const std::uint64_t length = u64();
    if (length > remaining()) fail();
    return {take(static_cast<std::size_t>(length)), static_cast<std::size_t>(length)};
  }
  std::span<const std::uint8_t> rest() {
    const std::size_t size = remaining();
    return {take(size), size};
  }
  StringMap string_map() {
    Cursor entries(bytes32(), record_);
    StringMap map;
    while (entries.remaining() > 0) {
      std::string key = entries.string();
      map[std::move(key)] = entries.string();
    }
    return map;
  }
  std::map<std::uint16_t, std::uint64_t> u16_u64_map() {
    Cursor entries(bytes32(), record_);
    std::map<std::uint16_t, std::uint64_t> map;
    while (entries.remaining() > 0) {
      const std::uint16_t key = entries.u16();
      map[key] = entries.u64();
    }
    return map;
  }
  std::vector<std::pair<std::uint64_t, std::uint64_t>> pairs() {
    Cursor entries(bytes32(), record_);
    std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
    while (entries.remaining() > 0) {
      const std::uint64_t first = entries.u64();
      out.emplace_back(first, entries.u64());
    }
    return out;
  }
  std::size_t remaining() const { return in_.size() - position_; }

 private:
  template <class T>
  T get() {
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  const std::uint8_t* take(std::size_t size) {
    if (size > remaining()) fail();
    const std::uint8_t* at = in_.data() + position_;
    position_ += size;
    return at;
  }
  [[noreturn]] void fail() const {
    throw FormatError(std::string("mcap: ") + record_ + " record ends inside a field");
  }

  std::span<const std::uint8_t> in_;
  std::size_t position_ = 0;
  const char* record_;
};

}  // namespace

void write_record(std::vector<std::uint8_t>& out, const Header& record) {
  RecordWriter w(out, Opcode::Header);
  w.string(record.profile);
  w.string(record.library);
}

void write_record(std::vector<std::uint8_t>& out, const Footer& record) {
  RecordWriter w(out, Opcode::Footer);
  w.u64(record.summary_start);
  w.u64(record.summary_offset_start);
  w.u32(record.summary_crc);
}

void write_record(std::vector<std::uint8_t>& out, const Schema& record) {
  RecordWriter w(out, Opcode::Schema);
  w.u16(record.id);
  w.string(record.name);
  w.string(record.encoding);
  w.bytes32(record.data);
}

void write_record(std::vector<std::uint8_t>& out, const Channel& record) {
  RecordWriter w(out, Opcode::Channel);
  w.u16(record.id);
  w.u16(record.schema_id);
  w.string(record.topic);
  w.string(record.message_encoding);
  w.string_map(record.metadata);
}

void write_message_record(std::vector<std::uint8_t>& out, std::uint16_t channel_id,
                          std::uint32_t sequence, std::uint64_t log_time,
                          std::uint64_t publish_time, std::span<const std::uint8_t> data) {
  RecordWriter w(out, Opcode::Message);
  w.u16(channel_id);
  w.u32(sequence);
  w.u64(log_time);
  w.u64(publish_time);
  w.raw(data);
}

void write_record(std::vector<std::uint8_t>& out, const Message& record) {
  write_message_record(out, record.channel_id, record.sequence, record.log_time,
                       record.publish_time, record.data);
}

void write_record(std::vector<std::uint8_t>& out, const Chunk& record) {
  RecordWriter w(out, Opcode::Chunk);
  w.u64(record.message_start_time);
  w.u64(record.message_end_time);
  w.u64(record.uncompressed_size);
  w.u32(record.uncompressed_crc);
  w.string(record.compression);
  w.bytes64(record.records);
}

void write_record(std::vector<std::uint8_t>& out, const MessageIndex& record) {
  RecordWriter w(out, Opcode::MessageIndex);
  w.u16(record.channel_id);
  w.pairs(record.records);
}

void write_record(std::vector<std::uint8_t>& out, const ChunkIndex& record) {
  RecordWriter w(out, Opcode::ChunkIndex);
  w.u64(record.message_start_time);
  w.u64(record.message_end_time);
  w.u64(record.chunk_start_offset);
  w.u64(record.chunk_length);
  w.u16_u64_map(record.message_index_offsets);
  w.u64(record.message_index_length);
  w.string(record.compression);
  w.u64(record.compressed_size);
  w.u64(record.uncompressed_size);
}

void write_record(std::vector<std::uint8_t>& out, const Statistics& record) {
  RecordWriter w(out, Opcode::Statistics);
  w.u64(record.message_count);
  w.u16(record.schema_count);
  w.u32(record.channel_count);
  w.u32(record.attachment_count);
  w.u32(record.metadata_count);
  w.u32(record.chunk_count);
  w.u64(record.message_start_time);
  w.u64(record.message_end_time);
  w.u16_u64_map(record.channel_message_counts);
}

void write_record(std::vector<std::uint8_t>& out, const Metadata& record) {
  RecordWriter w(out, Opcode::Metadata);
  w.string(record.name);
  w.string_map(record.metadata);
}

void write_record(std::vector<std::uint8_t>& out, const MetadataIndex& record) {
  RecordWriter w(out, Opcode::MetadataIndex);
  w.u64(record.offset);
  w.u64(record.length);
  w.string(record.name);
}

void write_record(std::vector<std::uint8_t>& out, const SummaryOffset& record) {
  RecordWriter w(out, Opcode::SummaryOffset);
  w.u8(record.group_opcode);
  w.u64(record.group_start);
  w.u64(record.group_length);
}

void write_record(std::vector<std::uint8_t>& out, const DataEnd& record) {
  RecordWriter w(out, Opcode::DataEnd);
  w.u32(record.data_section_crc);
}

Header parse_header(std::span<const std::uint8_t> content) {
  Cursor c(content, "Header");
  Header record;
  record.profile = c.string();
  record.library = c.string();
  return record;
}

Footer parse_footer(std::span<const std::uint8_t> content) {
  Cursor c(content, "Footer");
  Footer record;
  record.summary_start = c.u64();
  record.summary_offset_start = c.u64();
  record.summary_crc = c.u32();
  return record;
}

Schema parse_schema(std::span<const std::uint8_t> content) {
  Cursor c(content, "Schema");
  Schema record;
  record.id = c.u16();
  record.name = c.string();
  record.encoding = c.string();
  const auto data = c.bytes32();
  record.data.assign(data.begin(), data.end());
  return record;
}

Channel parse_channel(std::span<const std::uint8_t> content) {
  Cursor c(content, "Channel");
  Channel record;
  record.id = c.u16();
  record.schema_id = c.u16();
  record.topic = c.string();
  record.message_encoding = c.string();
  record.metadata = c.string_map();
  return record;
}

Message parse_message(std::span<const std::uint8_t> content) {
  Cursor c(content, "Message");
  Message record;
  record.channel_id = c.u16();
  record.sequence = c.u32();
  record.log_time = c.u64();
  record.publish_time = c.u64();
  const auto data = c.rest();
  record.data.assign(data.begin(), data.end());
  return record;
}

Chunk parse_chunk(std::span<const std::uint8_t> content) {
  Cursor c(content, "Chunk");
  Chunk record;
  record.message_start_time = c.u64();
  record.message_end_time = c.u64();
  record.uncompressed_size = c.u64();
  record.uncompressed_crc = c.u32();
  record.compression = c.string();
  const auto records = c.bytes64();
  record.records.assign(records.begin(), records.end());
  return record;
}

MessageIndex parse_message_index(std::span<const std::uint8_t> content) {
  Cursor c(content, "MessageIndex");
  MessageIndex record;
  record.channel_id = c.u16();
  record.records = c.pairs();
  return record;
}

ChunkIndex parse_chunk_index(std::span<const std::uint8_t> content) {
  Cursor c(content, "ChunkIndex");
  ChunkIndex record;
  record.message_start_time = c.u64();
  record.message_end_time = c.u64();
  record.chunk_start_offset = c.u64();
  record.chunk_length = c.u64();
  record.message_index_offsets = c.u16_u64_map();
  record.message_index_length = c.u64();
  record.compression = c.string();
  record.compressed_size = c.u64();
  record.uncompressed_size = c.u64();
  return record;
}

Statistics parse_statistics(std::span<const std::uint8_t> content) {
  Cursor c(content, "Statistics");
  Statistics record;
  record.message_count = c.u64();
  record.schema_count = c.u16();
  record.channel_count = c.u32();
  record.attachment_count = c.u32();
  record.metadata_count = c.u32();
  record.chunk_count = c.u32();
  record.message_start_time = c.u64();
  record.message_end_time = c.u64();
  record.channel_message_counts = c.u16_u64_map();
  return record;
}

Metadata parse_metadata(std::span<const std::uint8_t> content) {
  Cursor c(content, "Metadata");
  Metadata record;
  record.name = c.string();
  record.metadata = c.string_map();
  return record;
}

MetadataIndex parse_metadata_index(std::span<const std::uint8_t> content) {
  Cursor c(content, "MetadataIndex");
  MetadataIndex record;
  record.offset = c.u64();
  record.length = c.u64();
  record.name = c.string();
  return record;
}

SummaryOffset parse_summary_offset(std::span<const std::uint8_t> content) {
  Cursor c(content, "SummaryOffset");
  SummaryOffset record;
  record.group_opcode = c.u8();
  record.group_start = c.u64();
  record.group_length = c.u64();
  return record;
}

DataEnd parse_data_end(std::span<const std::uint8_t> content) {
  Cursor c(content, "DataEnd");
  DataEnd record;
  record.data_section_crc = c.u32();
  return record;
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) {
  // zlib takes uInt lengths: feed it in pieces below 4 GiB.
  constexpr std::size_t piece = std::size_t{1} << 30;
  uLong value = crc;
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    const std::size_t size = std::min(piece, bytes.size() - at);
    value = ::crc32(value, bytes.data() + at, static_cast<uInt>(size));
  }
  return static_cast<std::uint32_t>(value);
}

std::string_view compression_name(Compression compression) {
  switch (compression) {
    case Compression::Zstd:
      return "zstd";
    case Compression::Lz4:
      return "lz4";
    case Compression::None:
      break;
  }
  return "";
}

std::vector<std::uint8_t> compress(Compression compression, std::span<const std::uint8_t> bytes) {
  std::vector<std::uint8_t> out;
  switch (compression) {
    case Compression::None:
      out.assign(bytes.begin(), bytes.end());
      break;
    case Compression::Zstd: {
      out.resize(ZSTD_compressBound(bytes.size()));
      const std::size_t size = ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), 1);
      if (ZSTD_isError(size)) {
        throw FormatError(std::string("mcap: zstd compression failed: ") + ZSTD_getErrorName(size));
      }
      out.resize(size);
      break;
    }
    case Compression::Lz4: {
      LZ4F_preferences_t preferences{};
      preferences.frameInfo.contentSize = bytes.size();
      out.resize(LZ4F_compressFrameBound(bytes.size(), &preferences));
      const std::size_t size =
          LZ4F_compressFrame(out.data(), out.size(), bytes.data(), bytes.size(), &preferences);
      if (LZ4F_isError(size)) {
        throw FormatError(std::string("mcap: lz4 compression failed: ") + LZ4F_getErrorName(size));
      }
      out.resize(size);
      break;
    }
  }
  return out;
}

namespace {

// The output of a decompression, grown only as the codec really produces
// bytes: a declared size is a claim, never an allocation (a few bytes that
// declare terabytes cost what they decompress to, then a FormatError).
class GrowingOutput {
 public:
  GrowingOutput(std::uint64_t declared, std::size_t input_size) : declared_(declared) {
    const std::uint64_t first = std::min<std::uint64_t>(
        declared, std::max<std::uint64_t>(std::uint64_t{64} << 10, std::uint64_t{4} * input_size));
    out_.resize(static_cast<std::size_t>(first));
  }
  // Room after `written` bytes; grows (at most to the declared size) when full.
  std::span<std::uint8_t> room(std::size_t written) {
    if (written == out_.size() && out_.size() < declared_) {
      out_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(declared_, 2 * out_.size())));
    }
    return std::span(out_).subspan(written);
  }
  bool full(std::size_t written) const { return written == declared_; }
  std::vector<std::uint8_t> take(std::size_t written) {
    out_.resize(written);
    return std::move(out_);
  }

 private:
  const std::uint64_t declared_;
  std::vector<std::uint8_t> out_;
};

[[noreturn]] void shorter(const char* codec, std::size_t written, std::uint64_t declared) {
  throw FormatError(std::string("mcap: ") + codec + " chunk decompresses to " +
                    std::to_string(written) + " bytes, not the " + std::to_string(declared) +
                    " it declares");
}

std::vector<std::uint8_t> decompress_zstd(std::span<const std::uint8_t> bytes,
                                          std::uint64_t declared) {
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(),
                                                                     &ZSTD_freeDCtx);
  if (!context) throw FormatError("mcap: no zstd decompression context");
  GrowingOutput output(declared, bytes.size());
  ZSTD_inBuffer in{bytes.data(), bytes.size(), 0};
  std::size_t written = 0;
  for (;;) {
    const std::span<std::uint8_t> room = output.room(written);
    ZSTD_outBuffer out{room.data(), room.size(), 0};
    std::size_t hint = ZSTD_decompressStream(context.get(), &out, &in);
    if (ZSTD_isError(hint)) {
      throw FormatError(std::string("mcap: zstd chunk does not decompress: ") +
                        ZSTD_getErrorName(hint));
    }
    written += out.pos;
    if (in.pos == in.size && out.pos < out.size) break;  // all input used, all output out
    if (output.full(written)) {
      // What is left of the input must not decompress to a single byte more.
      while (hint != 0 || in.pos < in.size) {
        std::uint8_t extra = 0;
        ZSTD_outBuffer probe{&extra, 1, 0};
        const std::size_t consumed_before = in.pos;
        hint = ZSTD_decompressStream(context.get(), &probe, &in);
        if (ZSTD_isError(hint)) {
          throw FormatError(std::string("mcap: zstd chunk does not decompress: ") +
                            ZSTD_getErrorName(hint));
        }
        if (probe.pos > 0) {
          throw FormatError("mcap: zstd chunk decompresses to more than the " +
                            std::to_string(declared) + " bytes it declares");
        }
        if (in.pos == consumed_before) break;  // no progress: the input ends inside the frame
      }
      break;
    }
  }
  if (!output.full(written)) shorter("zstd", written, declared);
  return output.take(written);
}

std::vector<std::uint8_t> decompress_lz4(std::span<const std::uint8_t> bytes,
                                         std::uint64_t declared) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    throw FormatError("mcap: no lz4 decompression context");
  }
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(
      raw, &LZ4F_freeDecompressionContext);
  GrowingOutput output(declared, bytes.size());
  std::size_t written = 0;
  std::size_t read = 0;
  for (;;) {
    const std::span<std::uint8_t> room = output.room(written);
    // Once the declared size is reached, a byte of room: any output in it is too much.
    std::uint8_t extra = 0;
    const bool probing = output.full(written);
    std::size_t out_size = probing ? 1 : room.size();
    std::size_t in_size = bytes.size() - read;
    const std::size_t hint = LZ4F_decompress(context.get(), probing ? &extra : room.data(),
                                             &out_size, bytes.data() + read, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      throw FormatError(std::string("mcap: lz4 chunk does not decompress: ") +
                        LZ4F_getErrorName(hint));
    }
    if (probing && out_size > 0) {
      throw FormatError("mcap: lz4 chunk decompresses to more than the " +
                        std::to_string(declared) + " bytes it declares");
    }
    written += probing ? 0 : out_size;
    read += in_size;
    if (hint == 0) break;                      // the frame is complete
    if (in_size == 0 && out_size == 0) break;  // no progress: the input ends inside the frame
  }
  if (!output.full(written)) shorter("lz4", written, declared);
  return output.take(written);
}

}  // namespace

std::vector<std::uint8_t> decompress(std::string_view compression,
                                     std::span<const std::uint8_t> bytes,
                                     std::uint64_t uncompressed_size, std::uint64_t max_size) {
  if (uncompressed_size > max_size) {
    throw FormatError("mcap: a chunk declares " + std::to_string(uncompressed_size) +
                      " bytes of records, more than the " + std::to_string(max_size) +
                      " a chunk may hold (the reader's limit)");
  }
  if (compression.empty()) {
    if (bytes.size() != uncompressed_size) {
      throw FormatError("mcap: an uncompressed chunk's size differs from its declared size");
    }
    return {bytes.begin(), bytes.end()};
  }
  if (compression == "zstd") return decompress_zstd(bytes, uncompressed_size);
  if (compression == "lz4") return decompress_lz4(bytes, uncompressed_size);
  throw FormatError("mcap: unknown chunk compression '" + std::string(compression) + "'");
}

}  // namespace agnocast::mcap
