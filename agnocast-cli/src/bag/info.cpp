// agnocast-cli bag info FILE [--json]
#include <cstdio>
#include <map>
#include <set>
#include <system_error>

#include "agnocast/mcap/reader.hpp"
#include "bag/bag.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

struct TopicCount {
  std::string name;
  std::string type;
  std::string encoding;
  std::uint64_t messages = 0;
};

std::string compression_text(const std::set<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    if (!text.empty()) text += ",";
    text += name.empty() ? "none" : name;
  }
  return text.empty() ? "none" : text;
}

std::string time_text(std::uint64_t ns) {
  char buffer[64];
  const auto seconds = static_cast<std::time_t>(ns / 1000000000);
  std::tm local{};
  ::localtime_r(&seconds, &local);
  const std::size_t length = std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M:%S", &local);
  std::snprintf(buffer + length, sizeof buffer - length, ".%09llu (%llu)",
                static_cast<unsigned long long>(ns % 1000000000),
                static_cast<unsigned long long>(ns));
  return buffer;
}

std::string size_text(std::uint64_t bytes) {
  char buffer[32];
  if (bytes >= (1u << 30)) {
    std::snprintf(buffer, sizeof buffer, "%.1f GiB", static_cast<double>(bytes) / (1u << 30));
  } else if (bytes >= (1u << 20)) {
    std::snprintf(buffer, sizeof buffer, "%.1f MiB", static_cast<double>(bytes) / (1u << 20));
  } else if (bytes >= 1024) {
    std::snprintf(buffer, sizeof buffer, "%.1f KiB", static_cast<double>(bytes) / 1024);
  } else {
    std::snprintf(buffer, sizeof buffer, "%llu B", static_cast<unsigned long long>(bytes));
  }
  return buffer;
}

}  // namespace

nlohmann::json bag_info_json(const std::string& path) {
  std::optional<mcap::Reader> reader;
  try {
    reader.emplace(path);
  } catch (const mcap::FormatError& error) {
    throw InputError(error.what());
  } catch (const std::system_error& error) {
    throw InputError("cannot read " + path + ": " + error.code().message());
  }

  std::map<std::uint16_t, std::string> schema_names;
  std::map<std::uint16_t, TopicCount> channels;
  std::set<std::string> compressions;
  std::uint64_t messages = 0;
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;
  bool complete = false;
  std::string problem;

  auto add_channel = [&](const mcap::Channel& channel) {
    const auto schema = schema_names.find(channel.schema_id);
    channels[channel.id] =
        TopicCount{channel.topic, schema == schema_names.end() ? "" : schema->second,
                   channel.message_encoding, channels[channel.id].messages};
  };
  if (const auto& summary = reader->summary(); summary && summary->statistics) {
    complete = true;
    for (const mcap::Schema& schema : summary->schemas) schema_names[schema.id] = schema.name;
    for (const mcap::Channel& channel : summary->channels) add_channel(channel);
    const mcap::Statistics& statistics = *summary->statistics;
    for (const auto& [id, count] : statistics.channel_message_counts) channels[id].messages = count;
    for (const mcap::ChunkIndex& index : summary->chunk_indexes) {
      compressions.insert(index.compression);
    }
    messages = statistics.message_count;
    start_ns = statistics.message_start_time;
    end_ns = statistics.message_end_time;
  } else {
    // No summary: what the chunks hold, up to the last complete one.
    mcap::Visitor visitor;
    visitor.schema = [&](const mcap::Schema& schema) { schema_names[schema.id] = schema.name; };
    visitor.channel = add_channel;
    visitor.message = [&](const mcap::MessageView& message) {
      if (messages == 0 || message.log_time < start_ns) start_ns = message.log_time;
      if (messages == 0 || message.log_time > end_ns) end_ns = message.log_time;
      ++messages;
      ++channels[message.channel_id].messages;
    };
    const mcap::ScanResult result = reader->scan(visitor);
    compressions = result.compressions;
    problem = reader->summary() ? "the summary has no statistics" : reader->summary_problem();
    if (!result.stopped.empty()) problem += "; the data stops early: " + result.stopped;
  }

  const double duration_s = static_cast<double>(end_ns - start_ns) / 1e9;
  nlohmann::json topics = nlohmann::json::array();
  for (const auto& [id, topic] : channels) {
    topics.push_back(
        {{"name", topic.name},
         {"type", topic.type},
         {"encoding", topic.encoding},
         {"messages", topic.messages},
         {"rate_hz", duration_s > 0 ? static_cast<double>(topic.messages) / duration_s : 0.0}});
  }
  nlohmann::json value = {{"path", path},
                          {"size_bytes", reader->size()},
                          {"complete", complete},
                          {"compression", compression_text(compressions)},
                          {"start_ns", start_ns},
                          {"end_ns", end_ns},
                          {"duration_s", duration_s},
                          {"messages", messages},
                          {"topics", topics}};
  if (!complete) value["incomplete_reason"] = problem;
  return value;
}

std::string bag_info_table(const nlohmann::json& value) {
  std::string text;
  text += "File:        " + value["path"].get<std::string>() + "\n";
  text += "Size:        " + size_text(value["size_bytes"].get<std::uint64_t>()) + "\n";
  if (!value["complete"].get<bool>()) {
    text += "Incomplete:  " + value.value("incomplete_reason", std::string()) +
            " (shown: what the complete chunks hold)\n";
  }
  char duration[32];
  std::snprintf(duration, sizeof duration, "%.3f s", value["duration_s"].get<double>());
  text += "Duration:    " + std::string(duration) + "\n";
  if (value["messages"].get<std::uint64_t>() > 0) {
    text += "Start:       " + time_text(value["start_ns"].get<std::uint64_t>()) + "\n";
    text += "End:         " + time_text(value["end_ns"].get<std::uint64_t>()) + "\n";
  }
  text += "Messages:    " + std::to_string(value["messages"].get<std::uint64_t>()) + "\n";
  text += "Compression: " + value["compression"].get<std::string>() + "\n";
  Table table({{"TOPIC"},
               {"TYPE"},
               {"ENCODING"},
               {"MESSAGES", Table::Align::right},
               {"RATE_HZ", Table::Align::right}});
  for (const nlohmann::json& topic : value["topics"]) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.2f", topic["rate_hz"].get<double>());
    table.add_row({topic["name"].get<std::string>(), topic["type"].get<std::string>(),
                   topic["encoding"].get<std::string>(),
                   std::to_string(topic["messages"].get<std::uint64_t>()), rate});
  }
  return text + table.render();
}

}  // namespace agnocast::cli
