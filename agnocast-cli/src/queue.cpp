// agnocast-cli queue list: every agnocast-pattern notification queue but
// those of services, its depth read with mq_getattr, and whether a live
// subscriber still owns it.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <map>
#include <utility>

#include "agnocast/errors.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

// Queue name -> the live callback subscriber it belongs to. Without the module
// no subscriber can be alive, so every queue is then stale.
std::map<std::string, QueueOwner> live_queue_owners(InspectionSource& source) {
  std::vector<TopicSummary> summaries;
  try {
    summaries = source.list_topics();
  } catch (const ModuleNotLoaded&) {
    return {};
  }
  std::vector<TopicInfo> topics;
  for (const TopicSummary& summary : summaries) {
    // nullopt: the topic went away since it was listed.
    if (std::optional<TopicInfo> info = source.topic_info(summary.name)) {
      topics.push_back(std::move(*info));
    }
  }
  return queue_owners(topics);
}

}  // namespace

json queue_list_json(InspectionSource& source) {
  const std::map<std::string, QueueOwner> owners = live_queue_owners(source);
  std::vector<std::string> files = source.queue_files();
  std::sort(files.begin(), files.end());
  json queues = json::array();
  for (const std::string& file : files) {
    const std::optional<QueueNameParts> parts = parse_queue_name(file);
    if (!parts) continue;  // not an agnocast queue
    const std::string name = "/" + file;
    const auto owner = owners.find(name);
    const bool stale = owner == owners.end();
    // A service's queues belong to its server and clients (`service info`).
    if (!stale && is_service_topic(owner->second.topic)) continue;
    const auto attributes = source.queue_attributes(name);
    queues.push_back({{"name", name},
                      {"topic", stale ? json(nullptr) : json(owner->second.topic)},
                      {"subscriber_id", parts->subscriber_id},
                      {"pid", stale ? json(nullptr) : json(owner->second.pid)},
                      {"pending", attributes ? json(attributes->pending) : json(nullptr)},
                      {"capacity", attributes ? json(attributes->capacity) : json(nullptr)},
                      {"stale", stale}});
  }
  return {{"queues", queues}};
}

std::string queue_list_table(const json& value) {
  Table table({{"NAME"},
               {"TOPIC"},
               {"SUBSCRIBER_ID", Align::right},
               {"PID", Align::right},
               {"PENDING", Align::right},
               {"CAPACITY", Align::right},
               {"STALE"}});
  for (const json& q : value.at("queues")) {
    table.add_row({cell(q.at("name")), cell(q.at("topic")), cell(q.at("subscriber_id")),
                   cell(q.at("pid")), cell(q.at("pending")), cell(q.at("capacity")),
                   cell(q.at("stale"))});
  }
  return table.render();
}

void set_queue_command(CLI::App& app, Context& context) {
  CLI::App* queue = app.add_subcommand("queue", "Notification queues (POSIX mqueues)");
  queue->require_subcommand(1);
  CLI::App* list = queue->add_subcommand(
      "list", "Every agnocast queue with its depth; stale ones no live subscriber owns");
  bind_command(*list, context,
               {[&context] { return queue_list_json(context.source); }, queue_list_table});
}

}  // namespace agnocast::cli
