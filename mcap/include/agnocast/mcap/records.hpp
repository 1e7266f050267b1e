// The records of an MCAP file (mcap.dev, format version 0): what each one
// holds, how it is written and how it is read back. Little-endian; strings
// and maps carry a u32 byte length, a chunk's records and an attachment's data
// a u64 one; a record is opcode u8, content length u64, content.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace agnocast::mcap {

// Bytes that are not the MCAP the reader expected; what() says which and where.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// 0x89 "MCAP" '0' "\r\n": at the start and at the end of every file.
inline constexpr std::array<std::uint8_t, 8> magic{0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum class Opcode : std::uint8_t {
  Header = 0x01,
  Footer = 0x02,
  Schema = 0x03,
  Channel = 0x04,
  Message = 0x05,
  Chunk = 0x06,
  MessageIndex = 0x07,
  ChunkIndex = 0x08,
  Attachment = 0x09,
  AttachmentIndex = 0x0A,
  Statistics = 0x0B,
  Metadata = 0x0C,
  MetadataIndex = 0x0D,
  SummaryOffset = 0x0E,
  DataEnd = 0x0F,
};

// opcode + content length.
inline constexpr std::size_t record_prefix_size = 9;

using StringMap = std::map<std::string, std::string>;

struct Header {
  std::string profile;
  std::string library;
};

struct Footer {
  std::uint64_t summary_start = 0;  // 0: no summary section
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;  // 0: not computed
};

struct Schema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::vector<std::uint8_t> data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  StringMap metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::vector<std::uint8_t> data;
};

struct Chunk {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not computed
  std::string compression;             // "", "zstd" or "lz4"
  std::vector<std::uint8_t> records;   // as stored (compressed)
};

struct MessageIndex {
  std::uint16_t channel_id = 0;
  // (log_time, offset of the Message record in the chunk's uncompressed records)
  std::vector<std::pair<std::uint64_t, std::uint64_t>> records;
};

struct ChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

struct Metadata {
  std::string name;
  StringMap metadata;
};

struct MetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};

struct SummaryOffset {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
};

struct DataEnd {
  std::uint32_t data_section_crc = 0;  // 0: not computed
};

// Appends the whole record (opcode, length, content) to out.
void write_record(std::vector<std::uint8_t>& out, const Header& record);
void write_record(std::vector<std::uint8_t>& out, const Footer& record);
void write_record(std::vector<std::uint8_t>& out, const Schema& record);
void write_record(std::vector<std::uint8_t>& out, const Channel& record);
void write_record(std::vector<std::uint8_t>& out, const Message& record);
void write_record(std::vector<std::uint8_t>& out, const Chunk& record);
void write_record(std::vector<std::uint8_t>& out, const MessageIndex& record);
void write_record(std::vector<std::uint8_t>& out, const ChunkIndex& record);
void write_record(std::vector<std::uint8_t>& out, const Statistics& record);
void write_record(std::vector<std::uint8_t>& out, const Metadata& record);
void write_record(std::vector<std::uint8_t>& out, const MetadataIndex& record);
void write_record(std::vector<std::uint8_t>& out, const SummaryOffset& record);
void write_record(std::vector<std::uint8_t>& out, const DataEnd& record);
// A Message record whose data is not copied into a Message first.
void write_message_record(std::vector<std::uint8_t>& out, std::uint16_t channel_id,
                          std::uint32_t sequence, std::uint64_t log_time,
                          std::uint64_t publish_time, std::span<const std::uint8_t> data);

// Parse one record's content (after its opcode and length). Throw FormatError
// when the content ends inside a field; bytes after the known fields are
// ignored, as the format allows records to grow.
Header parse_header(std::span<const std::uint8_t> content);
Footer parse_footer(std::span<const std::uint8_t> content);
Schema parse_schema(std::span<const std::uint8_t> content);
Channel parse_channel(std::span<const std::uint8_t> content);
Message parse_message(std::span<const std::uint8_t> content);
Chunk parse_chunk(std::span<const std::uint8_t> content);
MessageIndex parse_message_index(std::span<const std::uint8_t> content);
ChunkIndex parse_chunk_index(std::span<const std::uint8_t> content);
Statistics parse_statistics(std::span<const std::uint8_t> content);
Metadata parse_metadata(std::span<const std::uint8_t> content);
MetadataIndex parse_metadata_index(std::span<const std::uint8_t> content);
SummaryOffset parse_summary_offset(std::span<const std::uint8_t> content);
DataEnd parse_data_end(std::span<const std::uint8_t> content);

// One record found in a byte range: its opcode and content.
struct RecordView {
  Opcode opcode;
  std::span<const std::uint8_t> content;
  std::size_t size() const { return record_prefix_size + content.size(); }
};

// CRC-32 (zlib's, ISO-HDLC), continuing from crc (0 to start).
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

// Chunk compression, by the name the format uses.
enum class Compression { None, Zstd, Lz4 };
std::string_view compression_name(Compression compression);  // "", "zstd", "lz4"
std::vector<std::uint8_t> compress(Compression compression, std::span<const std::uint8_t> bytes);

// The most a chunk's records may take uncompressed, 1 GiB: a reader holds one
// chunk's records at a time, so this bounds what reading any file costs,
// whatever it declares. The writer keeps its chunks within it.
inline constexpr std::uint64_t default_chunk_records_max = std::uint64_t{1} << 30;

// Throws FormatError for an unknown compression, an uncompressed_size over
// max_size (before decompressing anything) or bytes that do not decompress
// to exactly uncompressed_size bytes. The output grows (doubling) only as
// the codec produces bytes, never past the smaller of the two sizes.
std::vector<std::uint8_t> decompress(std::string_view compression,
                                     std::span<const std::uint8_t> bytes,
                                     std::uint64_t uncompressed_size,
                                     std::uint64_t max_size = default_chunk_records_max);

}  // namespace agnocast::mcap
