#include "agnocast/mcap/writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace agnocast::mcap {

Writer::Writer(std::string path, WriterOptions options)
    : path_(std::move(path)), options_(std::move(options)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), path_);
  std::vector<std::uint8_t> start(magic.begin(), magic.end());
  write_record(start, Header{options_.profile, options_.library});
  put(start, true);
}

Writer::~Writer() {
  if (!closed_) {
    try {
      close();
    } catch (...) {
      // The chunks already written stay readable; nothing more can be done here.
    }
  }
  if (fd_ >= 0) ::close(fd_);
}

void Writer::put(std::span<const std::uint8_t> bytes, bool data_section) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t written = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (written < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category(), path_);
    }
    done += static_cast<std::size_t>(written);
  }
  if (data_section) data_crc_ = crc32(bytes, data_crc_);
  offset_ += bytes.size();
}

std::uint16_t Writer::add_schema(std::string name, std::string encoding,
                                 std::vector<std::uint8_t> data) {
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back(Schema{id, std::move(name), std::move(encoding), std::move(data)});
  std::vector<std::uint8_t> record;
  write_record(record, schemas_.back());
  add_to_chunk(record);
  statistics_.schema_count = static_cast<std::uint16_t>(schemas_.size());
  return id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, std::string topic, std::string encoding,
                                  StringMap metadata) {
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back(
      Channel{id, schema_id, std::move(topic), std::move(encoding), std::move(metadata)});
  std::vector<std::uint8_t> record;
  write_record(record, channels_.back());
  add_to_chunk(record);
  statistics_.channel_count = static_cast<std::uint32_t>(channels_.size());
  statistics_.channel_message_counts[id] = 0;
  return id;
}

void Writer::write_message(std::uint16_t channel_id, std::uint64_t log_time,
                           std::uint64_t publish_time, std::span<const std::uint8_t> data) {
  if (data.size() > message_data_max) {
    throw FormatError("mcap: a message of " + std::to_string(data.size()) +
                      " bytes does not fit a chunk (at most " + std::to_string(message_data_max) +
                      " bytes of data, so that readers accept the chunk)");
  }
  if (chunk_records_.size() + message_record_overhead + data.size() > default_chunk_records_max) {
    flush_chunk();
  }
  MessageIndex& index = chunk_message_indexes_[channel_id];
  index.channel_id = channel_id;
  index.records.emplace_back(log_time, chunk_records_.size());
  write_message_record(chunk_records_, channel_id, sequences_[channel_id]++, log_time, publish_time,
                       data);
  if (!chunk_has_messages_ || log_time < chunk_start_time_) chunk_start_time_ = log_time;
  if (!chunk_has_messages_ || log_time > chunk_end_time_) chunk_end_time_ = log_time;
  if (statistics_.message_count == 0 || log_time < statistics_.message_start_time) {
    statistics_.message_start_time = log_time;
  }
  if (statistics_.message_count == 0 || log_time > statistics_.message_end_time) {
    statistics_.message_end_time = log_time;
  }
  chunk_has_messages_ = true;
  ++statistics_.message_count;
  ++statistics_.channel_message_counts[channel_id];
  if (chunk_records_.size() >= options_.chunk_size) flush_chunk();
}

void Writer::add_metadata(Metadata metadata) {
  // Metadata records live outside chunks: end the open one first, so the file stays in order.
  flush_chunk();
  std::vector<std::uint8_t> record;
  write_record(record, metadata);
  metadata_indexes_.push_back(MetadataIndex{offset_, record.size(), metadata.name});
  put(record, true);
  ++statistics_.metadata_count;
}

void Writer::add_to_chunk(std::span<const std::uint8_t> record) {
  if (chunk_records_.size() + record.size() > default_chunk_records_max) flush_chunk();
  chunk_records_.insert(chunk_records_.end(), record.begin(), record.end());
}

void Writer::flush_chunk() {
  if (chunk_records_.empty()) return;
  Chunk chunk;
  chunk.message_start_time = chunk_has_messages_ ? chunk_start_time_ : 0;
  chunk.message_end_time = chunk_has_messages_ ? chunk_end_time_ : 0;
  chunk.uncompressed_size = chunk_records_.size();
  chunk.uncompressed_crc = crc32(chunk_records_);
  chunk.compression = std::string(compression_name(options_.compression));
  chunk.records = compress(options_.compression, chunk_records_);

  ChunkIndex index;
  index.message_start_time = chunk.message_start_time;
  index.message_end_time = chunk.message_end_time;
  index.chunk_start_offset = offset_;
  index.compression = chunk.compression;
  index.compressed_size = chunk.records.size();
  index.uncompressed_size = chunk.uncompressed_size;

  std::vector<std::uint8_t> out;
  write_record(out, chunk);
  index.chunk_length = out.size();
  for (const auto& [channel_id, message_index] : chunk_message_indexes_) {
    index.message_index_offsets[channel_id] = offset_ + out.size();
    write_record(out, message_index);
  }
  index.message_index_length = out.size() - index.chunk_length;
  put(out, true);

  chunk_indexes_.push_back(std::move(index));
  ++statistics_.chunk_count;
  chunk_records_.clear();
  chunk_message_indexes_.clear();
  chunk_has_messages_ = false;
}

void Writer::close() {
  if (closed_) return;
  closed_ = true;  // whatever happens below, never twice
  flush_chunk();
  std::vector<std::uint8_t> out;
  write_record(out, DataEnd{data_crc_});
  put(out, false);

  // The summary, group by group, each noted in the summary offset section.
  const std::uint64_t summary_start = offset_;
  std::vector<std::uint8_t> summary;
  std::vector<SummaryOffset> offsets;
  auto group = [&](Opcode opcode, auto&& write_group) {
    const std::size_t start = summary.size();
    write_group();
    if (summary.size() > start) {
      offsets.push_back(SummaryOffset{static_cast<std::uint8_t>(opcode), summary_start + start,
                                      summary.size() - start});
    }
  };
  group(Opcode::Schema, [&] {
    for (const Schema& schema : schemas_) write_record(summary, schema);
  });
  group(Opcode::Channel, [&] {
    for (const Channel& channel : channels_) write_record(summary, channel);
  });
  group(Opcode::Statistics, [&] { write_record(summary, statistics_); });
  group(Opcode::ChunkIndex, [&] {
    for (const ChunkIndex& index : chunk_indexes_) write_record(summary, index);
  });
  group(Opcode::MetadataIndex, [&] {
    for (const MetadataIndex& index : metadata_indexes_) write_record(summary, index);
  });
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const SummaryOffset& offset : offsets) write_record(summary, offset);

  // The summary CRC covers the summary, the offsets and the footer up to the CRC itself.
  std::vector<std::uint8_t> footer;
  write_record(footer, Footer{summary_start, summary_offset_start, 0});
  std::uint32_t crc = crc32(summary);
  crc = crc32(std::span(footer).first(footer.size() - sizeof(std::uint32_t)), crc);
  footer.resize(footer.size() - sizeof(std::uint32_t));
  for (int i = 0; i < 4; ++i) footer.push_back(static_cast<std::uint8_t>(crc >> (8 * i)));
  summary.insert(summary.end(), footer.begin(), footer.end());
  summary.insert(summary.end(), magic.begin(), magic.end());
  put(summary, false);
  if (::fsync(fd_) != 0 && errno != EINVAL) {
    throw std::system_error(errno, std::generic_category(), path_);
  }
}

}  // namespace agnocast::mcap
