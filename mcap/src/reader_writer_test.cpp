#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "agnocast/mcap/reader.hpp"
#include "agnocast/mcap/writer.hpp"

namespace agnocast::mcap {
namespace {

namespace fs = std::filesystem;

struct Written {
  std::uint16_t channel;
  std::uint64_t log_time;
  std::vector<std::uint8_t> data;
};

class McapFile : public ::testing::TestWithParam<Compression> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("agnocast-mcap-test-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Two channels, messages of growing size, small chunks: several chunks.
  std::string write_sample(std::vector<Written>& written, std::size_t chunk_size = 512) {
    const std::string path = (dir_ / "sample.mcap").string();
    Writer writer(path, {.profile = "ros2", .compression = GetParam(), .chunk_size = chunk_size});
    const auto schema = writer.add_schema("std_msgs/msg/String", "ros2msg",
                                          {'s', 't', 'r', 'i', 'n', 'g', ' ', 'd'});
    const auto a = writer.add_channel(schema, "/a", "cdr", {{"offered_qos_profiles", ""}});
    const auto b = writer.add_channel(schema, "/b", "cdr", {});
    writer.add_metadata({"agnocast", {{"recorded_by", "test"}}});
    for (std::uint64_t i = 0; i < 60; ++i) {
      std::vector<std::uint8_t> data(4 + i % 37, static_cast<std::uint8_t>(i));
      const std::uint16_t channel = i % 3 == 0 ? b : a;
      writer.write_message(channel, 1000 + 10 * i, 900 + 10 * i, data);
      written.push_back({channel, 1000 + 10 * i, data});
    }
    EXPECT_EQ(writer.message_count(), 60u);
    writer.close();
    return path;
  }

  std::vector<Written> read_messages(const Reader& reader, ScanResult& result) {
    std::vector<Written> read;
    Visitor visitor;
    visitor.message = [&](const MessageView& m) {
      read.push_back({m.channel_id, m.log_time, {m.data.begin(), m.data.end()}});
    };
    result = reader.scan(visitor);
    return read;
  }

  fs::path dir_;
};

TEST_P(McapFile, WrittenFileReadsBackWithSummaryAndIndexes) {
  std::vector<Written> written;
  const std::string path = write_sample(written);
  const Reader reader(path);
  EXPECT_EQ(reader.header().profile, "ros2");
  EXPECT_EQ(reader.header().library, "agnocast");
  ASSERT_TRUE(reader.summary()) << reader.summary_problem();
  const Summary& summary = *reader.summary();
  ASSERT_EQ(summary.schemas.size(), 1u);
  EXPECT_EQ(summary.schemas[0].name, "std_msgs/msg/String");
  ASSERT_EQ(summary.channels.size(), 2u);
  EXPECT_EQ(summary.channels[0].topic, "/a");
  EXPECT_EQ(summary.channels[0].metadata.count("offered_qos_profiles"), 1u);
  ASSERT_TRUE(summary.statistics);
  EXPECT_EQ(summary.statistics->message_count, 60u);
  EXPECT_EQ(summary.statistics->channel_message_counts.at(1), 40u);
  EXPECT_EQ(summary.statistics->channel_message_counts.at(2), 20u);
  EXPECT_EQ(summary.statistics->message_start_time, 1000u);
  EXPECT_EQ(summary.statistics->message_end_time, 1590u);
  EXPECT_EQ(summary.statistics->metadata_count, 1u);
  EXPECT_GT(summary.chunk_indexes.size(), 3u);
  EXPECT_EQ(summary.statistics->chunk_count, summary.chunk_indexes.size());
  ASSERT_EQ(summary.metadata_indexes.size(), 1u);

  const auto bytes = reader.bytes();
  // The metadata index points at the Metadata record.
  const MetadataIndex& meta = summary.metadata_indexes[0];
  EXPECT_EQ(bytes[meta.offset], static_cast<std::uint8_t>(Opcode::Metadata));
  EXPECT_EQ(parse_metadata(bytes.subspan(meta.offset + 9, meta.length - 9)).name, "agnocast");

  // Each chunk index points at its chunk, and its message indexes at Message records.
  std::uint64_t indexed = 0;
  for (const ChunkIndex& index : summary.chunk_indexes) {
    ASSERT_EQ(bytes[index.chunk_start_offset], static_cast<std::uint8_t>(Opcode::Chunk));
    const Chunk chunk =
        parse_chunk(bytes.subspan(index.chunk_start_offset + 9, index.chunk_length - 9));
    EXPECT_EQ(chunk.compression, compression_name(GetParam()));
    EXPECT_EQ(index.compressed_size, chunk.records.size());
    const auto records = decompress(chunk.compression, chunk.records, chunk.uncompressed_size);
    EXPECT_EQ(crc32(records), chunk.uncompressed_crc);
    for (const auto& [channel, offset] : index.message_index_offsets) {
      ASSERT_EQ(bytes[offset], static_cast<std::uint8_t>(Opcode::MessageIndex));
      std::uint64_t length = 0;
      std::memcpy(&length, bytes.data() + offset + 1, 8);
      const MessageIndex message_index = parse_message_index(bytes.subspan(offset + 9, length));
      EXPECT_EQ(message_index.channel_id, channel);
      for (const auto& [log_time, at] : message_index.records) {
        ASSERT_EQ(records[at], static_cast<std::uint8_t>(Opcode::Message));
        std::uint64_t message_length = 0;
        std::memcpy(&message_length, records.data() + at + 1, 8);
        const MessageView message =
            parse_message_view(std::span(records).subspan(at + 9, message_length));
        EXPECT_EQ(message.channel_id, channel);
        EXPECT_EQ(message.log_time, log_time);
        EXPECT_GE(log_time, index.message_start_time);
        EXPECT_LE(log_time, index.message_end_time);
        ++indexed;
      }
    }
  }
  EXPECT_EQ(indexed, 60u);

  // The summary offsets name each group where it lies.
  const Footer& footer = summary.footer;
  std::size_t groups = 0;
  for (std::size_t at = footer.summary_offset_start; at < bytes.size() - 8 - 29;) {
    std::uint64_t length = 0;
    std::memcpy(&length, bytes.data() + at + 1, 8);
    ASSERT_EQ(bytes[at], static_cast<std::uint8_t>(Opcode::SummaryOffset));
    const SummaryOffset offset = parse_summary_offset(bytes.subspan(at + 9, length));
    EXPECT_EQ(bytes[offset.group_start], offset.group_opcode);
    ++groups;
    at += 9 + length;
  }
  EXPECT_EQ(groups, 5u);  // schemas, channels, statistics, chunk indexes, metadata indexes

  ScanResult result;
  const auto read = read_messages(reader, result);
  EXPECT_TRUE(result.reached_data_end) << result.stopped;
  EXPECT_EQ(result.chunks, summary.chunk_indexes.size());
  EXPECT_EQ(result.messages, 60u);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].channel, written[i].channel);
    EXPECT_EQ(read[i].log_time, written[i].log_time);
    EXPECT_EQ(read[i].data, written[i].data);
  }
}

TEST_P(McapFile, TruncatedAnywhereReadsUpToTheLastCompleteChunk) {
  std::vector<Written> written;
  const std::string path = write_sample(written);
  std::vector<char> whole(fs::file_size(path));
  std::ifstream(path, std::ios::binary)
      .read(whole.data(), static_cast<std::streamsize>(whole.size()));
  const std::string cut = (dir_ / "cut.mcap").string();
  std::size_t previous = 0;
  for (std::size_t size = 8; size < whole.size(); size += 7) {
    std::ofstream(cut, std::ios::binary | std::ios::trunc)
        .write(whole.data(), static_cast<std::streamsize>(size));
    std::optional<Reader> reader;
    try {
      reader.emplace(cut);
    } catch (const FormatError&) {
      EXPECT_LT(size, 40u) << "only a file cut inside its header is refused";
      continue;
    }
    EXPECT_FALSE(reader->summary());
    ScanResult result;
    const auto read = read_messages(*reader, result);
    // Short of the whole data section, the scan says why it stopped.
    EXPECT_EQ(result.reached_data_end, result.stopped.empty());
    if (read.size() < written.size()) {
      EXPECT_FALSE(result.reached_data_end);
    }
    // A prefix of what was written, never less than a shorter cut gave.
    ASSERT_LE(read.size(), written.size());
    EXPECT_GE(read.size(), previous);
    previous = read.size();
    for (std::size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i].data, written[i].data);
  }
  EXPECT_GT(previous, 40u);  // the last cuts lose at most the summary
}

TEST_P(McapFile, ADamagedChunkStopsTheScanThere) {
  std::vector<Written> written;
  const std::string path = write_sample(written, 1 << 20);  // one chunk
  std::vector<char> whole(fs::file_size(path));
  std::ifstream(path, std::ios::binary)
      .read(whole.data(), static_cast<std::streamsize>(whole.size()));
  {
    const Reader reader(path);
    const ChunkIndex index = reader.summary()->chunk_indexes.at(0);
    // A byte in the middle of the chunk's records.
    whole[index.chunk_start_offset + index.chunk_length - index.compressed_size / 2] ^= 0x5A;
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(whole.data(), static_cast<std::streamsize>(whole.size()));
  const Reader reader(path);
  ScanResult result;
  const auto read = read_messages(reader, result);
  EXPECT_FALSE(result.reached_data_end);
  EXPECT_TRUE(read.empty());
  EXPECT_FALSE(result.stopped.empty());
}

TEST_P(McapFile, ADamagedSummaryIsNoSummary) {
  std::vector<Written> written;
  const std::string path = write_sample(written);
  std::uint64_t summary_start = 0;
  {
    const Reader reader(path);
    summary_start = reader.summary()->footer.summary_start;
  }
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(static_cast<std::streamoff>(summary_start + 12));
  file.put('\x7f');
  file.close();
  const Reader reader(path);
  EXPECT_FALSE(reader.summary());
  EXPECT_NE(reader.summary_problem().find("CRC"), std::string::npos) << reader.summary_problem();
  ScanResult result;
  EXPECT_EQ(read_messages(reader, result).size(), 60u);
  EXPECT_TRUE(result.reached_data_end);
}

// Patches `bytes` at `offset` of the file with `value`'s bytes.
template <class T>
void patch(const std::string& path, std::uint64_t offset, T value) {
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(static_cast<std::streamoff>(offset));
  file.write(reinterpret_cast<const char*>(&value), sizeof value);
}

// Hostile files: every lie is a FormatError or a scan that stops and says
// why, never a crash, a read past the end or an allocation of a declared size.
TEST_P(McapFile, HostileLengthsSizesOpcodesAndCrcsStopTheScanCleanly) {
  std::vector<Written> written;
  const std::string original = write_sample(written, 1 << 20);  // one chunk
  ChunkIndex index;
  std::uint64_t summary_start = 0;
  {
    const Reader reader(original);
    ASSERT_TRUE(reader.summary());
    index = reader.summary()->chunk_indexes.at(0);
    summary_start = reader.summary()->footer.summary_start;
  }
  const std::uint64_t chunk = index.chunk_start_offset;
  // Chunk content: start and end times, then uncompressed_size, then its CRC.
  const std::uint64_t uncompressed_size_at = chunk + 9 + 16;
  const std::uint64_t uncompressed_crc_at = uncompressed_size_at + 8;
  const std::string path = (dir_ / "hostile.mcap").string();
  struct Case {
    const char* what;
    std::function<void()> damage;
  };
  const std::vector<Case> cases{
      {"a record length of 2^63", [&] { patch(path, chunk + 1, std::uint64_t{1} << 63); }},
      {"a record length one byte past the end",
       [&] { patch(path, chunk + 1, fs::file_size(path) - chunk - 9 + 1); }},
      {"a chunk declaring 2^60 uncompressed bytes",
       [&] { patch(path, uncompressed_size_at, std::uint64_t{1} << 60); }},
      {"a chunk declaring one byte more than it holds",
       [&] { patch(path, uncompressed_size_at, index.uncompressed_size + 1); }},
      {"a chunk declaring one byte less than it holds",
       [&] { patch(path, uncompressed_size_at, index.uncompressed_size - 1); }},
      {"a chunk's CRC wrong", [&] { patch(path, uncompressed_crc_at, std::uint32_t{0xDEADBEEF}); }},
      {"an unknown opcode instead of a chunk's", [&] { patch(path, chunk, std::uint8_t{0x7F}); }},
      {"a Footer's opcode instead of a chunk's",
       [&] { patch(path, chunk, static_cast<std::uint8_t>(Opcode::Footer)); }},
      {"a summary offset past the end",
       [&] { patch(path, fs::file_size(path) - magic.size() - 20, ~std::uint64_t{0} >> 1); }},
      {"a summary record length of 2^62",
       [&] { patch(path, summary_start + 1, std::uint64_t{1} << 62); }},
  };
  for (const Case& hostile : cases) {
    SCOPED_TRACE(hostile.what);
    fs::copy_file(original, path, fs::copy_options::overwrite_existing);
    hostile.damage();
    std::optional<Reader> reader;
    try {
      reader.emplace(path);
    } catch (const FormatError& error) {
      EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
      continue;
    }
    ScanResult result;
    const auto read = read_messages(*reader, result);
    EXPECT_EQ(result.reached_data_end, result.stopped.empty()) << result.stopped;
    ASSERT_LE(read.size(), written.size());
    for (std::size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i].data, written[i].data);
  }
}

INSTANTIATE_TEST_SUITE_P(All, McapFile,
                         ::testing::Values(Compression::None, Compression::Zstd, Compression::Lz4));

TEST(McapReader, RefusesWhatIsNotMcap) {
  const fs::path path = fs::temp_directory_path() / ("not-mcap-" + std::to_string(::getpid()));
  std::ofstream(path) << "hello, this is text and not MCAP at all";
  try {
    const Reader reader(path.string());
    ADD_FAILURE() << "a text file was read as MCAP";
  } catch (const FormatError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos);
  }
  fs::remove(path);
  EXPECT_THROW(Reader(path.string()), std::system_error);
}

TEST(McapWriter, DataSectionCrcIsChecked) {
  const fs::path path = fs::temp_directory_path() / ("crc-" + std::to_string(::getpid()) + ".mcap");
  {
    Writer writer(path.string(), {.profile = "", .compression = Compression::None});
    const auto channel = writer.add_channel(0, "/x", "json", {});
    writer.write_message(channel, 1, 1, std::vector<std::uint8_t>{'{', '}'});
  }  // the destructor closes it
  const Reader reader(path.string());
  ASSERT_TRUE(reader.summary());
  ScanResult result = reader.scan({});
  EXPECT_TRUE(result.reached_data_end) << result.stopped;
  EXPECT_EQ(result.messages, 1u);
  fs::remove(path);
}

}  // namespace
}  // namespace agnocast::mcap
