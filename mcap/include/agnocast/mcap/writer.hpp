// Writes an MCAP file as it goes: Schema and Channel records go into the chunk
// being filled, so every chunk on disk stands alone; a chunk is compressed,
// written and flushed once it holds chunk_size bytes, followed by its message
// indexes. close() writes the last chunk, DataEnd, the summary (schemas,
// channels, statistics, chunk and metadata indexes), the summary offsets, the
// footer and the closing magic. A process killed before close() leaves every
// chunk written so far readable.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "agnocast/mcap/records.hpp"

namespace agnocast::mcap {

// A Message record's bytes besides its data: prefix, channel id, sequence, two times.
inline constexpr std::uint64_t message_record_overhead = record_prefix_size + 2 + 4 + 8 + 8;
// The most data one message may carry: its record alone fills a chunk of
// default_chunk_records_max bytes, what readers accept.
inline constexpr std::uint64_t message_data_max =
    default_chunk_records_max - message_record_overhead;

struct WriterOptions {
  std::string profile;
  std::string library = "agnocast";
  Compression compression = Compression::Zstd;
  std::size_t chunk_size = std::size_t{1} << 20;
};

class Writer {
 public:
  // Creates (or truncates) path and writes the magic and Header. Throws
  // std::system_error naming the path when it cannot.
  Writer(std::string path, WriterOptions options);
  // Closes the file if close() was not called, ignoring errors.
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Ids start at 1 (0 means "no schema" to a channel).
  std::uint16_t add_schema(std::string name, std::string encoding, std::vector<std::uint8_t> data);
  std::uint16_t add_channel(std::uint16_t schema_id, std::string topic, std::string encoding,
                            StringMap metadata);
  // A chunk never grows past default_chunk_records_max: the open one is
  // written first when the message would not fit. Throws FormatError for data
  // over message_data_max.
  void write_message(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                     std::span<const std::uint8_t> data);
  void add_metadata(Metadata metadata);

  // Writes what is pending and the summary; the file is complete afterwards.
  // Throws std::system_error (a full disk, ...); the chunks written stay readable.
  void close();

  const std::string& path() const { return path_; }
  // Bytes in the file so far, and bytes waiting in the open chunk.
  std::uint64_t file_bytes() const { return offset_; }
  std::uint64_t pending_bytes() const { return chunk_records_.size(); }
  std::uint64_t message_count() const { return statistics_.message_count; }

 private:
  void flush_chunk();
  // Appends a record to the open chunk, written first if the record would not fit in it.
  void add_to_chunk(std::span<const std::uint8_t> record);
  void put(std::span<const std::uint8_t> bytes, bool data_section);

  std::string path_;
  WriterOptions options_;
  int fd_ = -1;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  bool closed_ = false;

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::map<std::uint16_t, std::uint32_t> sequences_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<MetadataIndex> metadata_indexes_;
  Statistics statistics_;

  // The open chunk: its records, uncompressed, and its message indexes.
  std::vector<std::uint8_t> chunk_records_;
  std::map<std::uint16_t, MessageIndex> chunk_message_indexes_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  bool chunk_has_messages_ = false;
};

}  // namespace agnocast::mcap
