// agnocast-cli bag play FILE [--rate X] [--loop] [--topics T...] [--start-offset SECONDS]
//
// Each channel is published with the type a compiled subscriber expects: the
// type name, layout hash and schema of the topic's live endpoints, or, when
// none exists yet, those bag record stored in the channel's metadata; a
// SchemaPublisher turns each message's CDR back into the message. Each
// publisher offers what the recorded ones offered (offered_qos_profiles):
// transient local and its depth, for subscribers that start after the player.
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <system_error>
#include <thread>

#include "agnocast/cdr.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/mcap/reader.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_publisher.hpp"
#include "agnocast/schema_topic.hpp"
#include "agnocast/signals.hpp"
#include "bag/bag.hpp"
#include "bag/definition_type.hpp"
#include "bag/qos_profiles.hpp"
#include "standard_types.hpp"

namespace agnocast::cli {
namespace {

std::vector<std::uint8_t> from_hex(const std::string& text) {
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < text.size(); i += 2) {
    bytes.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
  }
  return bytes;
}

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
  std::map<std::uint16_t, std::unique_ptr<SchemaPublisher>> channels;
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
    std::string type_name = schema->second.name;
    std::uint64_t type_hash = 0;
    std::vector<std::uint8_t> blob;
    std::optional<SchemaTopic> live;
    try {
      live = find_schema_topic(channel.topic);
    } catch (const Error& error) {  // a typed topic without schema, or an invalid one
      throw InputError(error.what());
    }
    if (live) {
      if (live->type_name != type_name) {
        throw InputError("topic '" + channel.topic + "' has type " + live->type_name +
                         ", the file's is " + type_name);
      }
      type_hash = live->type_hash;
      blob = std::move(live->blob);
    } else if (channel.metadata.contains("agnocast_schema")) {
      type_hash = std::stoull(channel.metadata.at("agnocast_type_hash"), nullptr, 16);
      blob = from_hex(channel.metadata.at("agnocast_schema"));
    } else if (const detail::MessageType* standard = standard_message_type(type_name)) {
      // A file from another tool, of a standard type: laid out as the
      // generated headers lay it out, which is what its subscribers expect.
      type_hash = standard->hash;
      blob.assign(standard->schema.begin(), standard->schema.end());
    } else {
      // Any other type: laid out from the definition the file carries, as
      // agnocast-msggen lays out the same .msg files for its subscribers.
      const std::vector<std::uint8_t>& text = schema->second.data;
      try {
        DefinitionType derived = type_from_definition(
            type_name, std::string_view(reinterpret_cast<const char*>(text.data()), text.size()));
        type_name = std::move(derived.type_name);
        type_hash = derived.type_hash;
        blob = std::move(derived.schema);
      } catch (const InputError& error) {
        throw InputError(options.path + ": topic '" + channel.topic + "' (" + type_name +
                         "): " + error.what());
      }
    }
    std::unique_ptr<SchemaPublisher> played;
    try {
      // A late subscriber gets what it would have got from the recorded publishers.
      const auto profiles = channel.metadata.find("offered_qos_profiles");
      const QoS qos = played_qos(
          profiles != channel.metadata.end() ? std::string_view(profiles->second) : "", 10);
      played = std::make_unique<SchemaPublisher>(node, channel.topic, qos, type_name, type_hash,
                                                 std::move(blob));
    } catch (const SchemaError& error) {
      throw InputError("topic '" + channel.topic + "': " + error.what());
    }
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
      SchemaPublisher& channel = *found->second;
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
      try {
        channel.publish_cdr(message.data);
      } catch (const cdr::Error&) {
        ++failed;
        return;
      }
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
