// agnocast-cli node list: endpoints grouped by process and node label.
#include <map>
#include <set>
#include <utility>

#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

struct Endpoints {
  std::set<std::string> publishes;
  std::set<std::string> subscribes;
};

}  // namespace

json node_list_json(InspectionSource& source) {
  // Ordered by pid, then label: a node is a label within one process.
  std::map<std::pair<pid_t, std::string>, Endpoints> nodes;
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const PublisherInfo& p : info->publishers) {
      nodes[{p.pid, p.node}].publishes.insert(info->name);
    }
    for (const SubscriberInfo& s : info->subscribers) {
      nodes[{s.pid, s.node}].subscribes.insert(info->name);
    }
  }
  json list = json::array();
  for (const auto& [key, endpoints] : nodes) {
    list.push_back({{"name", key.second},
                    {"pid", key.first},
                    {"publishes", endpoints.publishes},
                    {"subscribes", endpoints.subscribes}});
  }
  return {{"nodes", list}};
}

std::string node_list_table(const json& value) {
  Table table({{"NAME"}, {"PID", Align::right}, {"PUBLISHES"}, {"SUBSCRIBES"}});
  for (const json& n : value.at("nodes")) {
    table.add_row(
        {cell(n.at("name")), cell(n.at("pid")), cell(n.at("publishes")), cell(n.at("subscribes"))});
  }
  return table.render();
}

void set_node_command(CLI::App& app, Context& context) {
  CLI::App* node = app.add_subcommand("node", "Nodes: the labelled endpoints of each process");
  node->require_subcommand(1);
  CLI::App* list = node->add_subcommand("list", "Every node with the topics it uses");
  bind_command(*list, context,
               {[&context] { return node_list_json(context.source); }, node_list_table});
}

}  // namespace agnocast::cli
