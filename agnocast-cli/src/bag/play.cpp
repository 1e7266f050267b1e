// agnocast-cli bag play FILE [--rate X] [--loop] [--topics T...] [--start-offset SECONDS]
//
// Each channel is published with the type a compiled subscriber expects: the
// type name, layout hash and schema of the topic's live endpoints, or, when
// none exists yet, those bag record stored in the channel's metadata. A
// message's CDR is turned back into the message in one pool block: the
// message, then the elements of its sequences and the characters of its
// long strings, so the block's release frees everything.
#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <system_error>
#include <thread>

#include "agnocast/cdr.hpp"
#include "agnocast/detail/endpoints.hpp"
#include "agnocast/detail/message.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/mcap/reader.hpp"
#include "agnocast/node.hpp"
#include "agnocast/signals.hpp"
#include "bag/bag.hpp"
#include "standard_types.hpp"

namespace agnocast::cli {
namespace {

void leave_to_block(void*) {}  // the block holds everything: freeing it is all

// Reads XCDR1 (after the encapsulation header) into a message laid out as
// the schema says, containers as libstdc++ lays them out. A first pass
// (memory == nullptr) only measures what the block needs after the message.
class CdrToPool {
 public:
  CdrToPool(const Schema& schema, std::span<const std::uint8_t> payload)
      : schema_(schema), in_(payload) {}

  std::size_t measure() {
    dry_ = true;
    position_ = 0;
    tail_ = schema_.types[0].size;
    message(schema_.types[0], nullptr);
    return tail_;
  }

  void fill(std::byte* block) {
    dry_ = false;
    position_ = 0;
    block_ = block;
    tail_ = schema_.types[0].size;
    std::memset(block, 0, schema_.types[0].size);
    message(schema_.types[0], block);
  }

 private:
  [[noreturn]] static void fail(const std::string& what) { throw cdr::Error("cdr: " + what); }
  void align(std::size_t size) {
    const std::size_t pad = (size - position_ % size) % size;
    take(pad);
  }
  const std::uint8_t* take(std::size_t bytes) {
    if (bytes > in_.size() - position_) fail("input ends inside the message");
    const std::uint8_t* at = in_.data() + position_;
    position_ += bytes;
    return at;
  }
  std::uint32_t count() {
    align(4);
    std::uint32_t value;
    std::memcpy(&value, take(4), 4);
    return value;
  }
  std::byte* reserve(std::size_t bytes, std::size_t align_to) {
    align_to = std::max<std::size_t>(align_to, 1);
    tail_ = (tail_ + align_to - 1) / align_to * align_to;
    std::byte* at = dry_ ? nullptr : block_ + tail_;
    tail_ += bytes;
    return at;
  }
  void store_pointer(std::byte* at, const void* pointer) {
    if (!dry_) std::memcpy(at, &pointer, sizeof pointer);
  }

  void message(const SchemaType& type, std::byte* at) {
    for (const SchemaField& field : type.fields) {
      std::byte* value = at ? at + field.offset : nullptr;
      switch (field.shape) {
        case FieldShape::Single:
          elements(field, value, 1);
          break;
        case FieldShape::Array:
          elements(field, value, field.array_length);
          break;
        case FieldShape::Sequence: {
          const std::uint32_t n = count();
          if (field.sequence_bound != 0 && n > field.sequence_bound) {
            fail("sequence '" + field.name + "' longer than its bound");
          }
          // Every element takes at least a byte: a longer count is a lie, not an allocation.
          if (n > in_.size() - position_)
            fail("sequence '" + field.name + "' longer than the input");
          const std::size_t bytes = static_cast<std::size_t>(n) * field.element_size;
          std::byte* first = reserve(bytes, field.element_align);
          if (!dry_) std::memset(first, 0, bytes);
          const ContainerLayout& layout = schema_.containers;
          store_pointer(value + layout.vector_begin_offset, first);
          store_pointer(value + layout.vector_end_offset, first + bytes);
          // libstdc++'s third pointer, the end of storage.
          store_pointer(value + 2 * layout.pointer_size, first + bytes);
          elements(field, first, n);
          break;
        }
      }
    }
  }

  void primitives(std::byte* at, std::size_t size, std::size_t n) {
    if (n == 0) return;
    align(size);
    const std::uint8_t* bytes = take(size * n);
    if (!dry_) std::memcpy(at, bytes, size * n);
  }

  void elements(const SchemaField& field, std::byte* at, std::size_t n) {
    switch (field.kind) {
      case FieldKind::Bool:
      case FieldKind::Int8:
      case FieldKind::UInt8:
        return primitives(at, 1, n);
      case FieldKind::Int16:
      case FieldKind::UInt16:
        return primitives(at, 2, n);
      case FieldKind::Int32:
      case FieldKind::UInt32:
      case FieldKind::Float32:
        return primitives(at, 4, n);
      case FieldKind::Int64:
      case FieldKind::UInt64:
      case FieldKind::Float64:
        return primitives(at, 8, n);
      case FieldKind::String:
        for (std::size_t i = 0; i < n; ++i)
          string(field, at ? at + i * field.element_size : nullptr);
        return;
      case FieldKind::Message:
        for (std::size_t i = 0; i < n; ++i) {
          message(schema_.types[field.nested], at ? at + i * field.element_size : nullptr);
        }
        return;
      case FieldKind::Opaque:
        break;
    }
    fail("field '" + field.name + "' holds opaque bytes, which have no CDR form");
  }

  void string(const SchemaField& field, std::byte* at) {
    const std::uint32_t length = count();
    if (length == 0) fail("string '" + field.name + "' of length 0 (it counts the NUL)");
    const auto* chars = take(length);
    if (chars[length - 1] != 0) fail("string '" + field.name + "' not terminated by NUL");
    const std::size_t size = length - 1;
    if (field.string_bound != 0 && size > field.string_bound) {
      fail("string '" + field.name + "' longer than its bound");
    }
    const ContainerLayout& layout = schema_.containers;
    // libstdc++: pointer, length, then 16 bytes of local buffer or the capacity.
    constexpr std::size_t local_offset = 16;
    constexpr std::size_t local_capacity = 15;
    std::byte* data =
        size <= local_capacity ? (at ? at + local_offset : nullptr) : reserve(size + 1, 1);
    if (dry_) return;
    std::memcpy(data, chars, size);
    data[size] = std::byte{0};
    store_pointer(at + layout.string_data_offset, data);
    std::memcpy(at + layout.string_length_offset, &size, sizeof size);
    if (size > local_capacity) std::memcpy(at + local_offset, &size, sizeof size);
  }

  const Schema& schema_;
  std::span<const std::uint8_t> in_;
  std::size_t position_ = 0;
  std::size_t tail_ = 0;
  std::byte* block_ = nullptr;
  bool dry_ = true;
};

// The layout this reader writes: libstdc++'s, on a 64-bit machine.
bool supported_layout(const ContainerLayout& layout) {
  return layout.pointer_size == 8 && layout.vector_size == 24 && layout.vector_begin_offset == 0 &&
         layout.vector_end_offset == 8 && layout.string_size == 32 &&
         layout.string_data_offset == 0 && layout.string_length_offset == 8;
}

std::vector<std::uint8_t> from_hex(const std::string& text) {
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < text.size(); i += 2) {
    bytes.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
  }
  return bytes;
}

struct PlayedChannel {
  std::string topic;
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::vector<std::uint8_t> blob;
  Schema schema;
  std::unique_ptr<detail::PublisherCore> publisher;
};

struct Stop {};

}  // namespace

int bag_play(const BagPlayOptions& options, std::ostream& out) {
  std::optional<mcap::Reader> reader;
  try {
    reader.emplace(options.path);
  } catch (const mcap::FormatError& error) {
    throw InputError(error.what());
  } catch (const std::system_error& error) {
    throw InputError("cannot read " + options.path + ": " + error.code().message());
  }
  install_signal_handlers();
  Node node("agnocast_bag_play");
  std::map<std::uint16_t, mcap::Schema> schemas;
  std::map<std::uint16_t, std::unique_ptr<PlayedChannel>> channels;
  const std::set<std::string> wanted(options.topics.begin(), options.topics.end());

  auto open_channel = [&](const mcap::Channel& channel) {
    if (channels.contains(channel.id)) return;
    if (!wanted.empty() && !wanted.contains(channel.topic)) {
      channels[channel.id] = nullptr;
      return;
    }
    const auto schema = schemas.find(channel.schema_id);
    if (schema == schemas.end() || schema->second.encoding != "ros2msg" ||
        channel.message_encoding != "cdr") {
      throw InputError(options.path + ": topic '" + channel.topic +
                       "' is not ros2msg schemas with cdr messages (encoding '" +
                       channel.message_encoding + "')");
    }
    auto played = std::make_unique<PlayedChannel>();
    played->topic = channel.topic;
    played->type_name = schema->second.name;
    if (const auto info = topic_info(channel.topic)) {
      if (info->type_name != played->type_name) {
        throw InputError("topic '" + channel.topic + "' has type " + info->type_name +
                         ", the file's is " + played->type_name);
      }
      played->type_hash = info->type_hash;
      played->blob = topic_schema(channel.topic).value_or(std::vector<std::uint8_t>{});
    } else if (channel.metadata.contains("agnocast_schema")) {
      played->type_hash = std::stoull(channel.metadata.at("agnocast_type_hash"), nullptr, 16);
      played->blob = from_hex(channel.metadata.at("agnocast_schema"));
    } else if (const detail::MessageType* standard = standard_message_type(played->type_name)) {
      // A file from another tool, of a standard type: laid out as the
      // generated headers lay it out, which is what its subscribers expect.
      played->type_hash = standard->hash;
      played->blob.assign(standard->schema.begin(), standard->schema.end());
    }
    if (played->blob.empty()) {
      throw InputError(options.path + ": no layout known for topic '" + channel.topic + "' (" +
                       played->type_name +
                       ", not a standard type): start a subscriber of it first, or record the "
                       "file with agnocast");
    }
    try {
      played->schema = parse_schema(played->blob);
    } catch (const SchemaError& error) {
      throw InputError("topic '" + channel.topic + "': " + error.what());
    }
    if (!supported_layout(played->schema.containers)) {
      throw InputError("topic '" + channel.topic +
                       "': bag play writes libstdc++ containers on 64-bit machines only");
    }
    played->publisher = std::make_unique<detail::PublisherCore>(
        node.state(), channel.topic, QoS(10),
        detail::MessageType{played->type_name, played->type_hash, played->blob});
    channels[channel.id] = std::move(played);
  };

  std::optional<std::uint64_t> first_time;
  if (const auto& summary = reader->summary(); summary && summary->statistics) {
    first_time = summary->statistics->message_start_time;
  }
  const auto offset_ns = static_cast<std::uint64_t>(options.start_offset_s * 1e9);
  std::uint64_t published = 0;
  std::uint64_t failed = 0;
  do {
    std::optional<std::chrono::steady_clock::time_point> start;
    mcap::Visitor visitor;
    visitor.schema = [&](const mcap::Schema& schema) { schemas[schema.id] = schema; };
    visitor.channel = open_channel;
    visitor.message = [&](const mcap::MessageView& message) {
      if (!agnocast::ok()) throw Stop{};
      if (!first_time) first_time = message.log_time;
      if (message.log_time < *first_time + offset_ns) return;
      const auto found = channels.find(message.channel_id);
      if (found == channels.end() || !found->second) return;
      PlayedChannel& channel = *found->second;
      const std::uint64_t since = message.log_time - *first_time - offset_ns;
      const auto now = std::chrono::steady_clock::now();
      if (!start)
        start = now - std::chrono::nanoseconds(static_cast<std::int64_t>(since / options.rate));
      const auto due =
          *start + std::chrono::nanoseconds(static_cast<std::int64_t>(since / options.rate));
      while (std::chrono::steady_clock::now() < due) {
        if (!agnocast::ok()) throw Stop{};
        std::this_thread::sleep_until(
            std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(50)));
      }
      if (message.data.size() < 4 || message.data[0] != 0 || message.data[1] != 1) {
        ++failed;
        return;
      }
      CdrToPool decoder(channel.schema, message.data.subspan(4));
      std::size_t size = 0;
      try {
        size = decoder.measure();
      } catch (const cdr::Error&) {
        ++failed;
        return;
      }
      void* memory = detail::allocate_message(
          size, std::max<std::size_t>(channel.schema.types[0].align, 8), &leave_to_block);
      decoder.fill(static_cast<std::byte*>(memory));
      channel.publisher->publish(memory, size);
      ++published;
    };
    try {
      const mcap::ScanResult result = reader->scan(visitor);
      if (!result.reached_data_end && !result.stopped.empty()) {
        out << "agnocast-cli: " << options.path << " ends early (" << result.stopped
            << "): played what it holds\n";
      }
    } catch (const Stop&) {
      break;
    }
  } while (options.loop && agnocast::ok());
  out << "Played " << published << " messages from " << options.path;
  if (failed > 0) out << "; " << failed << " could not be decoded and were skipped";
  out << '\n';
  return exit_success;
}

}  // namespace agnocast::cli
