// agnocast-cli topic list | info TOPIC (hz: topic_hz.cpp, delay: topic_delay.cpp, echo:
// echo.cpp)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

json pending_of(InspectionSource& source, const std::optional<std::string>& queue) {
  if (!queue) return nullptr;
  const auto attributes = source.queue_attributes(*queue);
  return attributes ? json(attributes->pending) : json(nullptr);
}

// A topic's type, null for one whose endpoints declared none.
json type_of(const std::string& type_name) {
  return type_name.empty() ? json(nullptr) : json(type_name);
}

std::string hex64(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

const CLI::Validator topic_name_validator(
    [](std::string& topic) { return topic_name_problem(topic); }, "TOPIC", "topic name");

}  // namespace

TopicInfo require_topic(InspectionSource& source, const std::string& topic) {
  std::optional<TopicInfo> info = source.topic_info(topic);
  if (!info) {
    throw CliError("no publisher or subscriber uses topic '" + topic +
                   "'; `agnocast-cli topic list` shows the topics that exist");
  }
  return *info;
}

json topic_list_json(InspectionSource& source) {
  std::vector<TopicSummary> topics = source.list_topics();
  std::sort(topics.begin(), topics.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  json list = json::array();
  for (const TopicSummary& topic : topics) {
    if (is_service_topic(topic.name)) continue;  // `service list` shows those
    list.push_back({{"name", topic.name},
                    {"type", type_of(topic.type_name)},
                    {"publishers", topic.publishers},
                    {"subscribers", topic.subscribers}});
  }
  return {{"topics", list}};
}

json topic_info_json(InspectionSource& source, const std::string& topic) {
  TopicInfo info = require_topic(source, topic);
  auto by_id = [](const auto& a, const auto& b) { return a.id < b.id; };
  std::sort(info.publishers.begin(), info.publishers.end(), by_id);
  std::sort(info.subscribers.begin(), info.subscribers.end(), by_id);

  json publishers = json::array();
  for (const PublisherInfo& p : info.publishers) {
    publishers.push_back({{"id", p.id},
                          {"pid", p.pid},
                          {"node", p.node},
                          {"depth", p.depth},
                          {"transient_local", p.transient_local},
                          {"published", p.published},
                          {"uid", p.uid}});
  }
  json subscribers = json::array();
  for (const SubscriberInfo& s : info.subscribers) {
    // Polling subscribers are never woken, so they own no queue.
    const std::optional<std::string> queue =
        s.polling ? std::nullopt : std::optional(queue_name(info.name, s.id));
    subscribers.push_back({{"id", s.id},
                           {"pid", s.pid},
                           {"node", s.node},
                           {"depth", s.depth},
                           {"queue", queue ? json(*queue) : json(nullptr)},
                           {"pending", pending_of(source, queue)},
                           {"unreceived", s.unreceived},
                           {"dropped", s.dropped},
                           {"uid", s.uid},
                           {"transient_local", s.transient_local},
                           {"polling", s.polling},
                           {"held", s.held},
                           {"received", s.received}});
  }
  return {{"name", info.name},
          {"type", type_of(info.type_name)},
          {"type_hash", hex64(info.type_hash)},
          {"publishers", publishers},
          {"subscribers", subscribers}};
}

std::string topic_list_table(const json& value) {
  Table table({{"NAME"}, {"TYPE"}, {"PUBLISHERS", Align::right}, {"SUBSCRIBERS", Align::right}});
  for (const json& t : value.at("topics")) {
    table.add_row({cell(t.at("name")), cell(t.at("type")), cell(t.at("publishers")),
                   cell(t.at("subscribers"))});
  }
  return table.render();
}

std::string topic_info_table(const json& value) {
  Table publishers({{"ID", Align::right},
                    {"PID", Align::right},
                    {"UID", Align::right},
                    {"NODE"},
                    {"DEPTH", Align::right},
                    {"TRANSIENT_LOCAL"},
                    {"PUBLISHED", Align::right}});
  for (const json& p : value.at("publishers")) {
    publishers.add_row({cell(p.at("id")), cell(p.at("pid")), cell(p.at("uid")), cell(p.at("node")),
                        cell(p.at("depth")), cell(p.at("transient_local")),
                        cell(p.at("published"))});
  }
  Table subscribers({{"ID", Align::right},
                     {"PID", Align::right},
                     {"UID", Align::right},
                     {"NODE"},
                     {"DEPTH", Align::right},
                     {"TRANSIENT_LOCAL"},
                     {"QUEUE"},
                     {"PENDING", Align::right},
                     {"UNRECEIVED", Align::right},
                     {"HELD", Align::right},
                     {"RECEIVED", Align::right},
                     {"DROPPED", Align::right}});
  for (const json& s : value.at("subscribers")) {
    // A polling subscriber has no queue: its QUEUE cell says so.
    const json queue = s.at("polling").get<bool>() ? json("(polling)") : s.at("queue");
    subscribers.add_row({cell(s.at("id")), cell(s.at("pid")), cell(s.at("uid")), cell(s.at("node")),
                         cell(s.at("depth")), cell(s.at("transient_local")), cell(queue),
                         cell(s.at("pending")), cell(s.at("unreceived")), cell(s.at("held")),
                         cell(s.at("received")), cell(s.at("dropped"))});
  }
  return "topic " + cell(value.at("name")) + "\ntype  " + cell(value.at("type")) +
         (value.at("type").is_null() ? std::string() : " (" + cell(value.at("type_hash")) + ")") +
         "\n\npublishers\n" + publishers.render() + "\nsubscribers\n" + subscribers.render();
}

void set_topic_command(CLI::App& app, Context& context) {
  CLI::App* topic = app.add_subcommand("topic", "Topics, their endpoints and publish rates");
  topic->require_subcommand(1);

  CLI::App* list = topic->add_subcommand("list", "Every topic with its endpoint counts");
  bind_command(*list, context,
               {[&context] { return topic_list_json(context.source); }, topic_list_table});

  auto name = std::make_shared<std::string>();
  CLI::App* info = topic->add_subcommand("info", "Publishers and subscribers of one topic");
  info->add_option("TOPIC", *name, "Topic name, e.g. /chatter")
      ->required()
      ->check(topic_name_validator);
  bind_command(
      *info, context,
      {[&context, name] { return topic_info_json(context.source, *name); }, topic_info_table});

  set_topic_hz_command(*topic, context);
  set_topic_delay_command(*topic, context);
  set_topic_echo_command(*topic, context);
}

}  // namespace agnocast::cli
