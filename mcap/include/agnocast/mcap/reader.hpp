// Reads an MCAP file: its summary when the file has a valid one, and its data
// section record by record (chunks decompressed and CRC-checked), stopping
// cleanly at the first record that is cut short or corrupt, so that a file
// whose writer died is read up to its last complete chunk.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "agnocast/mcap/records.hpp"

namespace agnocast::mcap {

// A Message record whose data points into the chunk or file being read.
struct MessageView {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::span<const std::uint8_t> data;
};
MessageView parse_message_view(std::span<const std::uint8_t> content);

struct Summary {
  Footer footer;
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  std::optional<Statistics> statistics;
  std::vector<ChunkIndex> chunk_indexes;
  std::vector<MetadataIndex> metadata_indexes;
};

// What a walk of the data section met; the callbacks left empty are not called.
struct Visitor {
  std::function<void(const Schema&)> schema;
  std::function<void(const Channel&)> channel;
  std::function<void(const MessageView&)> message;
  std::function<void(const Metadata&)> metadata;
  // A chunk, before its records are visited.
  std::function<void(const Chunk&)> chunk;
};

struct ScanResult {
  // true when the walk reached DataEnd; false when it stopped before.
  bool reached_data_end = false;
  // Why it stopped before DataEnd (cut short, a CRC mismatch, ...), else empty.
  std::string stopped;
  std::uint64_t chunks = 0;
  std::uint64_t messages = 0;
  std::set<std::string> compressions;  // as named in the chunks, "" for none
};

struct ReaderOptions {
  // A chunk declaring more records than this stops the scan before any is
  // decompressed (default_chunk_records_max).
  std::uint64_t chunk_records_max = default_chunk_records_max;
};

class Reader {
 public:
  // Maps path. Throws FormatError naming the path when it does not start with
  // the MCAP magic and a Header, std::system_error when it cannot be read.
  explicit Reader(std::string path, ReaderOptions options = {});
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const std::string& path() const { return path_; }
  std::uint64_t size() const { return size_; }
  const Header& header() const { return header_; }

  // The summary, when the file ends with a Footer and the magic, the footer
  // points at a summary and the summary's CRC (when set) holds.
  const std::optional<Summary>& summary() const { return summary_; }
  // Why summary() is empty.
  const std::string& summary_problem() const { return summary_problem_; }

  // Walks the data section in file order. Never throws for a damaged file:
  // the result says where and why it stopped (a chunk over the limit, a chunk
  // holding a record other than Schema, Channel and Message, ...). Besides
  // the mapped file it holds one chunk as stored and its records: at most
  // chunk_records_max bytes, 1.5 times that while their buffer doubles.
  // Exceptions from the callbacks pass.
  ScanResult scan(const Visitor& visitor, bool verify_crcs = true) const;

  std::span<const std::uint8_t> bytes() const { return {data_, size_}; }

 private:
  void read_summary();

  std::string path_;
  ReaderOptions options_;
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  Header header_;
  std::size_t data_start_ = 0;
  std::optional<Summary> summary_;
  std::string summary_problem_;
};

}  // namespace agnocast::mcap
