#include "agnocast/mcap/records.hpp"

#include <gtest/gtest.h>

#include <cstring>

namespace agnocast::mcap {
namespace {

std::vector<std::uint8_t> bytes_of(std::string_view text) { return {text.begin(), text.end()}; }

// The content of the single record in out, after checking its opcode and length.
std::span<const std::uint8_t> content_of(const std::vector<std::uint8_t>& out, Opcode opcode) {
  EXPECT_GE(out.size(), record_prefix_size);
  EXPECT_EQ(out[0], static_cast<std::uint8_t>(opcode));
  std::uint64_t length = 0;
  std::memcpy(&length, out.data() + 1, sizeof length);
  EXPECT_EQ(length, out.size() - record_prefix_size);
  return std::span(out).subspan(record_prefix_size);
}

template <class Record, class Parse>
Record round_trip(const Record& record, Opcode opcode, Parse parse) {
  std::vector<std::uint8_t> out;
  write_record(out, record);
  const Record back = parse(content_of(out, opcode));
  // Every byte counts: the record cut by one byte no longer parses.
  const auto content = content_of(out, opcode);
  if (!content.empty()) {
    EXPECT_THROW(parse(content.first(content.size() - 1)), FormatError);
  }
  return back;
}

TEST(McapRecords, HeaderBytesAreTheSpecsLayout) {
  std::vector<std::uint8_t> out;
  write_record(out, Header{"ros2", "ab"});
  const std::vector<std::uint8_t> expected{0x01, 14, 0, 0, 0,   0,   0,   0,   0,  // opcode, length
                                           4,    0,  0, 0, 'r', 'o', 's', '2',     //
                                           2,    0,  0, 0, 'a', 'b'};
  EXPECT_EQ(out, expected);
  const Header back = round_trip(Header{"ros2", "ab"}, Opcode::Header, parse_header);
  EXPECT_EQ(back.profile, "ros2");
  EXPECT_EQ(back.library, "ab");
}

TEST(McapRecords, Footer) {
  const Footer back = round_trip(Footer{123, 456, 0xDEADBEEF}, Opcode::Footer, parse_footer);
  EXPECT_EQ(back.summary_start, 123u);
  EXPECT_EQ(back.summary_offset_start, 456u);
  EXPECT_EQ(back.summary_crc, 0xDEADBEEFu);
}

TEST(McapRecords, Schema) {
  const Schema back =
      round_trip(Schema{7, "std_msgs/msg/String", "ros2msg", bytes_of("string data")},
                 Opcode::Schema, parse_schema);
  EXPECT_EQ(back.id, 7);
  EXPECT_EQ(back.name, "std_msgs/msg/String");
  EXPECT_EQ(back.encoding, "ros2msg");
  EXPECT_EQ(back.data, bytes_of("string data"));
}

TEST(McapRecords, ChannelWithMetadata) {
  const Channel channel{
      3, 7, "/chatter", "cdr", {{"offered_qos_profiles", "- depth: 10"}, {"a", ""}}};
  const Channel back = round_trip(channel, Opcode::Channel, parse_channel);
  EXPECT_EQ(back.id, 3);
  EXPECT_EQ(back.schema_id, 7);
  EXPECT_EQ(back.topic, "/chatter");
  EXPECT_EQ(back.message_encoding, "cdr");
  EXPECT_EQ(back.metadata, channel.metadata);
}

TEST(McapRecords, MessageKeepsItsDataToTheRecordsEnd) {
  std::vector<std::uint8_t> out;
  write_record(out, Message{2, 9, 1000, 999, {0, 1, 0, 0, 42}});
  EXPECT_EQ(out.size(), record_prefix_size + 2 + 4 + 8 + 8 + 5);
  const Message back = parse_message(content_of(out, Opcode::Message));
  EXPECT_EQ(back.channel_id, 2);
  EXPECT_EQ(back.sequence, 9u);
  EXPECT_EQ(back.log_time, 1000u);
  EXPECT_EQ(back.publish_time, 999u);
  EXPECT_EQ(back.data, (std::vector<std::uint8_t>{0, 1, 0, 0, 42}));
  EXPECT_THROW(parse_message(content_of(out, Opcode::Message).first(21)), FormatError);
}

TEST(McapRecords, Chunk) {
  const Chunk back =
      round_trip(Chunk{10, 20, 5, 0x1234, "zstd", {1, 2, 3}}, Opcode::Chunk, parse_chunk);
  EXPECT_EQ(back.message_start_time, 10u);
  EXPECT_EQ(back.message_end_time, 20u);
  EXPECT_EQ(back.uncompressed_size, 5u);
  EXPECT_EQ(back.uncompressed_crc, 0x1234u);
  EXPECT_EQ(back.compression, "zstd");
  EXPECT_EQ(back.records, (std::vector<std::uint8_t>{1, 2, 3}));
}

TEST(McapRecords, MessageIndex) {
  const MessageIndex back =
      round_trip(MessageIndex{4, {{100, 0}, {200, 57}}}, Opcode::MessageIndex, parse_message_index);
  EXPECT_EQ(back.channel_id, 4);
  EXPECT_EQ(back.records,
            (std::vector<std::pair<std::uint64_t, std::uint64_t>>{{100, 0}, {200, 57}}));
}

TEST(McapRecords, ChunkIndex) {
  const ChunkIndex index{1, 2, 30, 40, {{1, 70}, {2, 90}}, 50, "lz4", 60, 80};
  const ChunkIndex back = round_trip(index, Opcode::ChunkIndex, parse_chunk_index);
  EXPECT_EQ(back.message_start_time, 1u);
  EXPECT_EQ(back.message_end_time, 2u);
  EXPECT_EQ(back.chunk_start_offset, 30u);
  EXPECT_EQ(back.chunk_length, 40u);
  EXPECT_EQ(back.message_index_offsets, index.message_index_offsets);
  EXPECT_EQ(back.message_index_length, 50u);
  EXPECT_EQ(back.compression, "lz4");
  EXPECT_EQ(back.compressed_size, 60u);
  EXPECT_EQ(back.uncompressed_size, 80u);
}

TEST(McapRecords, Statistics) {
  const Statistics statistics{100, 2, 3, 0, 1, 4, 5, 6, {{1, 60}, {3, 40}}};
  const Statistics back = round_trip(statistics, Opcode::Statistics, parse_statistics);
  EXPECT_EQ(back.message_count, 100u);
  EXPECT_EQ(back.schema_count, 2);
  EXPECT_EQ(back.channel_count, 3u);
  EXPECT_EQ(back.attachment_count, 0u);
  EXPECT_EQ(back.metadata_count, 1u);
  EXPECT_EQ(back.chunk_count, 4u);
  EXPECT_EQ(back.message_start_time, 5u);
  EXPECT_EQ(back.message_end_time, 6u);
  EXPECT_EQ(back.channel_message_counts, statistics.channel_message_counts);
}

TEST(McapRecords, MetadataAndItsIndex) {
  const Metadata back =
      round_trip(Metadata{"rosbag2", {{"k", "v"}}}, Opcode::Metadata, parse_metadata);
  EXPECT_EQ(back.name, "rosbag2");
  EXPECT_EQ(back.metadata, (StringMap{{"k", "v"}}));
  const MetadataIndex index =
      round_trip(MetadataIndex{11, 22, "rosbag2"}, Opcode::MetadataIndex, parse_metadata_index);
  EXPECT_EQ(index.offset, 11u);
  EXPECT_EQ(index.length, 22u);
  EXPECT_EQ(index.name, "rosbag2");
}

TEST(McapRecords, SummaryOffsetAndDataEnd) {
  const SummaryOffset offset =
      round_trip(SummaryOffset{0x03, 1000, 77}, Opcode::SummaryOffset, parse_summary_offset);
  EXPECT_EQ(offset.group_opcode, 0x03);
  EXPECT_EQ(offset.group_start, 1000u);
  EXPECT_EQ(offset.group_length, 77u);
  EXPECT_EQ(round_trip(DataEnd{0xCAFEF00D}, Opcode::DataEnd, parse_data_end).data_section_crc,
            0xCAFEF00Du);
}

TEST(McapRecords, AMapWhoseLengthLiesIsAFormatError) {
  std::vector<std::uint8_t> out;
  write_record(out, Metadata{"m", {{"key", "value"}}});
  auto content = std::vector<std::uint8_t>(out.begin() + record_prefix_size, out.end());
  content[5] = 200;  // the map's byte length, now beyond the record
  EXPECT_THROW(parse_metadata(content), FormatError);
}

TEST(McapCrc, IsZlibsCrc32) {
  EXPECT_EQ(crc32(bytes_of("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32({}), 0u);
  // Continued in pieces, it is the same as at once.
  EXPECT_EQ(crc32(bytes_of("56789"), crc32(bytes_of("1234"))), 0xCBF43926u);
}

class McapCompression : public ::testing::TestWithParam<Compression> {};

TEST_P(McapCompression, RoundTripsAndRejectsDamage) {
  std::vector<std::uint8_t> input(100000);
  for (std::size_t i = 0; i < input.size(); ++i) input[i] = static_cast<std::uint8_t>(i % 251 / 7);
  const auto packed = compress(GetParam(), input);
  const std::string name(compression_name(GetParam()));
  if (GetParam() != Compression::None) {
    EXPECT_LT(packed.size(), input.size() / 4);
  }
  EXPECT_EQ(decompress(name, packed, input.size()), input);
  EXPECT_THROW(decompress(name, packed, input.size() + 1), FormatError);
  EXPECT_THROW(decompress(name, std::span(packed).first(packed.size() / 2), input.size()),
               FormatError);
}

INSTANTIATE_TEST_SUITE_P(All, McapCompression,
                         ::testing::Values(Compression::None, Compression::Zstd, Compression::Lz4));

TEST(McapCompression, NamesAndUnknown) {
  EXPECT_EQ(compression_name(Compression::None), "");
  EXPECT_EQ(compression_name(Compression::Zstd), "zstd");
  EXPECT_EQ(compression_name(Compression::Lz4), "lz4");
  EXPECT_THROW(decompress("brotli", bytes_of("x"), 1), FormatError);
  // A declared size no codec reaches from so few bytes is refused before allocating it.
  EXPECT_THROW(decompress("zstd", bytes_of("x"), std::uint64_t{1} << 40), FormatError);
}

// A chunk whose declared size lies far above what its bytes hold: a
// FormatError once the real output ends, never an allocation of the lie (a
// vector of 2^62 bytes would throw std::length_error or std::bad_alloc here).
TEST_P(McapCompression, AHugeDeclaredSizeIsAFormatErrorNotAnAllocation) {
  if (GetParam() == Compression::None) GTEST_SKIP() << "stored as is: the sizes must agree";
  std::vector<std::uint8_t> input(100000);
  for (std::size_t i = 0; i < input.size(); ++i) input[i] = static_cast<std::uint8_t>(i * 31 / 7);
  const auto packed = compress(GetParam(), input);
  const std::string name(compression_name(GetParam()));
  for (const std::uint64_t lie :
       {std::uint64_t{1} << 40, std::uint64_t{1} << 62, ~std::uint64_t{0}}) {
    try {
      decompress(name, packed, lie);
      ADD_FAILURE() << "declared " << lie << " accepted";
    } catch (const FormatError& error) {
      EXPECT_NE(std::string(error.what()).find(std::to_string(lie)), std::string::npos)
          << error.what();
    }
  }
  EXPECT_THROW(decompress(name, packed, input.size() - 1), FormatError) << "more than declared";
}

// Highly compressible records (a zeroed 4 MiB point cloud) decompress,
// whatever their ratio.
TEST_P(McapCompression, ZerosDecompressWhateverTheRatio) {
  const std::vector<std::uint8_t> zeros(4 << 20, 0);
  const auto packed = compress(GetParam(), zeros);
  EXPECT_EQ(decompress(compression_name(GetParam()), packed, zeros.size()), zeros);
}

}  // namespace
}  // namespace agnocast::mcap
