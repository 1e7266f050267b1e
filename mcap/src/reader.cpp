#include "agnocast/mcap/reader.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <optional>
#include <system_error>

namespace agnocast::mcap {
namespace {

// "Chunk (0x06)", or "opcode 0x7f" for one the format does not define.
std::string opcode_name(std::uint8_t opcode) {
  static constexpr const char* names[] = {
      nullptr,    "Header",        "Footer",        "Schema",     "Channel",         "Message",
      "Chunk",    "MessageIndex",  "ChunkIndex",    "Attachment", "AttachmentIndex", "Statistics",
      "Metadata", "MetadataIndex", "SummaryOffset", "DataEnd"};
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", opcode);
  if (opcode < std::size(names) && names[opcode] != nullptr) {
    return std::string(names[opcode]) + " (" + hex + ")";
  }
  return std::string("opcode ") + hex;
}

// A chunk holds Schema, Channel and Message records, and may hold records
// the format does not define (a reader skips those); any other record, a
// Chunk above all, is damage.
bool belongs_in_chunk(Opcode opcode) {
  const auto value = static_cast<std::uint8_t>(opcode);
  return opcode == Opcode::Schema || opcode == Opcode::Channel || opcode == Opcode::Message ||
         value < static_cast<std::uint8_t>(Opcode::Header) ||
         value > static_cast<std::uint8_t>(Opcode::DataEnd);
}

// The record at offset `at` of bytes, or nullopt when it does not fit
// (problem says why).
std::optional<RecordView> record_at(std::span<const std::uint8_t> bytes, std::size_t at,
                                    std::string& problem) {
  if (bytes.size() - at < record_prefix_size) {
    problem = "cut short inside a record's opcode and length at byte " + std::to_string(at);
    return std::nullopt;
  }
  std::uint64_t length = 0;
  std::memcpy(&length, bytes.data() + at + 1, sizeof length);
  if (length > bytes.size() - at - record_prefix_size) {
    problem = "cut short inside a record (" + opcode_name(bytes[at]) + ", " +
              std::to_string(length) + " bytes) at byte " + std::to_string(at);
    return std::nullopt;
  }
  return RecordView{static_cast<Opcode>(bytes[at]),
                    bytes.subspan(at + record_prefix_size, static_cast<std::size_t>(length))};
}

}  // namespace

MessageView parse_message_view(std::span<const std::uint8_t> content) {
  constexpr std::size_t fixed = 2 + 4 + 8 + 8;
  if (content.size() < fixed) throw FormatError("mcap: Message record ends inside a field");
  MessageView view;
  std::memcpy(&view.channel_id, content.data(), 2);
  std::memcpy(&view.sequence, content.data() + 2, 4);
  std::memcpy(&view.log_time, content.data() + 6, 8);
  std::memcpy(&view.publish_time, content.data() + 14, 8);
  view.data = content.subspan(fixed);
  return view;
}

Reader::Reader(std::string path, ReaderOptions options)
    : path_(std::move(path)), options_(options) {
  const int fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), path_);
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    throw std::system_error(error, std::generic_category(), path_);
  }
  if (!S_ISREG(info.st_mode)) {
    ::close(fd);
    throw FormatError(path_ + ": not a regular file");
  }
  size_ = static_cast<std::size_t>(info.st_size);
  if (size_ > 0) {
    void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapped == MAP_FAILED) {
      const int error = errno;
      ::close(fd);
      throw std::system_error(error, std::generic_category(), path_);
    }
    data_ = static_cast<const std::uint8_t*>(mapped);
  }
  ::close(fd);

  const std::span<const std::uint8_t> all = bytes();
  if (size_ < magic.size() || std::memcmp(data_, magic.data(), magic.size()) != 0) {
    throw FormatError(path_ + ": not an MCAP file (it does not start with the MCAP magic)");
  }
  std::string problem;
  const auto header = record_at(all, magic.size(), problem);
  if (!header || header->opcode != Opcode::Header) {
    throw FormatError(path_ + ": not an MCAP file (no Header record after the magic)");
  }
  try {
    header_ = parse_header(header->content);
  } catch (const FormatError& error) {
    throw FormatError(path_ + ": " + error.what());
  }
  data_start_ = magic.size() + header->size();
  read_summary();
}

Reader::~Reader() {
  if (data_) ::munmap(const_cast<std::uint8_t*>(data_), size_);
}

void Reader::read_summary() {
  const std::span<const std::uint8_t> all = bytes();
  constexpr std::size_t footer_size = record_prefix_size + 8 + 8 + 4;
  if (size_ < data_start_ + footer_size + magic.size() ||
      std::memcmp(data_ + size_ - magic.size(), magic.data(), magic.size()) != 0) {
    summary_problem_ = "the file does not end with a footer and the MCAP magic";
    return;
  }
  const std::size_t footer_at = size_ - magic.size() - footer_size;
  if (all[footer_at] != static_cast<std::uint8_t>(Opcode::Footer)) {
    summary_problem_ = "no Footer record before the closing magic";
    return;
  }
  Footer footer;
  try {
    footer = parse_footer(all.subspan(footer_at + record_prefix_size, footer_size - 9));
  } catch (const FormatError& error) {
    summary_problem_ = error.what();
    return;
  }
  if (footer.summary_start == 0) {
    summary_problem_ = "the footer points at no summary";
    return;
  }
  if (footer.summary_start < data_start_ || footer.summary_start > footer_at) {
    summary_problem_ = "the footer's summary offset lies outside the file";
    return;
  }
  const std::size_t start = static_cast<std::size_t>(footer.summary_start);
  if (footer.summary_crc != 0) {
    const std::uint32_t crc = crc32(all.subspan(start, footer_at + footer_size - 4 - start));
    if (crc != footer.summary_crc) {
      summary_problem_ = "the summary's CRC does not match";
      return;
    }
  }
  std::size_t end = footer_at;
  if (footer.summary_offset_start != 0 && footer.summary_offset_start >= footer.summary_start &&
      footer.summary_offset_start <= footer_at) {
    end = static_cast<std::size_t>(footer.summary_offset_start);
  }
  Summary summary;
  summary.footer = footer;
  try {
    for (std::size_t at = start; at < end;) {
      std::string problem;
      const auto record = record_at(all.first(end), at, problem);
      if (!record) {
        summary_problem_ = "summary " + problem;
        return;
      }
      switch (record->opcode) {
        case Opcode::Schema:
          summary.schemas.push_back(parse_schema(record->content));
          break;
        case Opcode::Channel:
          summary.channels.push_back(parse_channel(record->content));
          break;
        case Opcode::Statistics:
          summary.statistics = parse_statistics(record->content);
          break;
        case Opcode::ChunkIndex:
          summary.chunk_indexes.push_back(parse_chunk_index(record->content));
          break;
        case Opcode::MetadataIndex:
          summary.metadata_indexes.push_back(parse_metadata_index(record->content));
          break;
        default:
          break;  // attachment indexes and records this reader does not use
      }
      at += record->size();
    }
  } catch (const FormatError& error) {
    summary_problem_ = std::string("summary: ") + error.what();
    return;
  }
  summary_ = std::move(summary);
}

ScanResult Reader::scan(const Visitor& visitor, bool verify_crcs) const {
  ScanResult result;
  const std::span<const std::uint8_t> all = bytes();
  // The records of the chunk at byte chunk_at of the file, or one record outside chunks.
  auto visit_records = [&](std::span<const std::uint8_t> records,
                           std::optional<std::size_t> chunk_at) -> bool {
    for (std::size_t at = 0; at < records.size();) {
      std::string problem;
      const auto record = record_at(records, at, problem);
      if (!record) {
        result.stopped = (chunk_at ? "a chunk's records are " : "") + problem;
        return false;
      }
      if (chunk_at && !belongs_in_chunk(record->opcode)) {
        result.stopped = "the chunk at byte " + std::to_string(*chunk_at) + " holds a " +
                         opcode_name(records[at]) + " record (at byte " + std::to_string(at) +
                         " of its records): a chunk holds only Schema, Channel and Message "
                         "records";
        return false;
      }
      switch (record->opcode) {
        case Opcode::Schema:
          if (visitor.schema) visitor.schema(parse_schema(record->content));
          break;
        case Opcode::Channel:
          if (visitor.channel) visitor.channel(parse_channel(record->content));
          break;
        case Opcode::Message:
          ++result.messages;
          if (visitor.message) visitor.message(parse_message_view(record->content));
          break;
        default:
          break;
      }
      at += record->size();
    }
    return true;
  };

  std::uint32_t data_crc = crc32(all.first(data_start_));
  for (std::size_t at = data_start_; at < size_;) {
    std::string problem;
    const auto record = record_at(all, at, problem);
    if (!record) {
      result.stopped = problem;
      return result;
    }
    try {
      switch (record->opcode) {
        case Opcode::DataEnd: {
          const DataEnd end = parse_data_end(record->content);
          if (verify_crcs && end.data_section_crc != 0 && end.data_section_crc != data_crc) {
            result.stopped = "the data section's CRC does not match";
            return result;
          }
          result.reached_data_end = true;
          return result;
        }
        case Opcode::Chunk: {
          const Chunk chunk = parse_chunk(record->content);
          const std::vector<std::uint8_t> records =
              decompress(chunk.compression, chunk.records, chunk.uncompressed_size,
                         options_.chunk_records_max);
          if (verify_crcs && chunk.uncompressed_crc != 0 &&
              crc32(records) != chunk.uncompressed_crc) {
            result.stopped = "the chunk at byte " + std::to_string(at) + " fails its CRC";
            return result;
          }
          ++result.chunks;
          result.compressions.insert(chunk.compression);
          if (visitor.chunk) visitor.chunk(chunk);
          if (!visit_records(records, at)) return result;
          break;
        }
        case Opcode::Metadata:
          if (visitor.metadata) visitor.metadata(parse_metadata(record->content));
          break;
        case Opcode::Footer:
          result.stopped = "a Footer before any DataEnd";
          return result;
        default:
          if (!visit_records(all.subspan(at, record->size()), std::nullopt)) return result;
          break;
      }
    } catch (const FormatError& error) {
      result.stopped = std::string(error.what()) + " at byte " + std::to_string(at);
      return result;
    }
    data_crc = crc32(all.subspan(at, record->size()), data_crc);
    at += record->size();
  }
  result.stopped = "the file ends before its DataEnd record";
  return result;
}

}  // namespace agnocast::mcap
