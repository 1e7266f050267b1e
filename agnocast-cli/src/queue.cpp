// agnocast-cli queue list: every agnocast-pattern notification queue, its
// depth read with mq_getattr, and whether a live subscriber still owns it.
#include <algorithm>
#include <map>

#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

struct Owner {
  std::string topic;
  pid_t pid = 0;
};

// Queue name -> the live callback subscriber it belongs to. Without the module
// no subscriber can be alive, so every queue is then stale.
std::map<std::string, Owner> queue_owners(InspectionSource& source) {
  std::map<std::string, Owner> owners;
  std::vector<TopicSummary> topics;
  try {
    topics = source.list_topics();
  } catch (const ModuleNotLoaded&) {
    return owners;
  }
  for (const TopicSummary& summary : topics) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const SubscriberInfo& s : info->subscribers) {
      if (!s.polling) owners.emplace(queue_name(info->name, s.id), Owner{info->name, s.pid});
    }
  }
  return owners;
}

}  // namespace

json queue_list_json(InspectionSource& source) {
  const std::map<std::string, Owner> owners = queue_owners(source);
  std::vector<std::string> files = source.queue_files();
  std::sort(files.begin(), files.end());
  json queues = json::array();
  for (const std::string& file : files) {
    const std::optional<QueueNameParts> parts = parse_queue_name(file);
    if (!parts) continue;  // not an agnocast queue
    const std::string name = "/" + file;
    const auto owner = owners.find(name);
    const bool stale = owner == owners.end();
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
