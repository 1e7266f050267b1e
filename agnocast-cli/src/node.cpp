// agnocast-cli node list | info NODE: endpoints grouped by process and node label.
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

json node_info_json(InspectionSource& source, const std::string& node) {
  std::set<pid_t> pids;
  // topic -> type, per direction; a node publishing a topic from two pids lists it once.
  std::map<std::string, std::string> publishes;
  std::map<std::string, std::string> subscribes;
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const PublisherInfo& p : info->publishers) {
      if (p.node != node) continue;
      pids.insert(p.pid);
      publishes[info->name] = info->type_name;
    }
    for (const SubscriberInfo& s : info->subscribers) {
      if (s.node != node) continue;
      pids.insert(s.pid);
      subscribes[info->name] = info->type_name;
    }
  }
  if (pids.empty()) {
    throw CliError("no endpoint belongs to node '" + node +
                   "'; `agnocast-cli node list` shows the nodes that exist");
  }
  const auto endpoints = [](const std::map<std::string, std::string>& topics) {
    json list = json::array();
    for (const auto& [topic, type] : topics) {
      list.push_back({{"topic", topic}, {"type", type.empty() ? json(nullptr) : json(type)}});
    }
    return list;
  };
  return {{"name", node},
          {"pids", pids},
          {"publishers", endpoints(publishes)},
          {"subscribers", endpoints(subscribes)}};
}

std::string node_info_table(const json& value) {
  Table endpoints({{"DIRECTION"}, {"TOPIC"}, {"TYPE"}});
  for (const char* direction : {"publishers", "subscribers"}) {
    for (const json& e : value.at(direction)) {
      endpoints.add_row({direction == std::string("publishers") ? "publishes" : "subscribes",
                         cell(e.at("topic")), cell(e.at("type"))});
    }
  }
  return "node " + cell(value.at("name")) + "\npids " + cell(value.at("pids")) + "\n\n" +
         endpoints.render();
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
  auto name = std::make_shared<std::string>();
  CLI::App* info = node->add_subcommand("info", "The processes and topics of one node");
  info->add_option("NODE", *name, "Node name, e.g. talker")->required();
  bind_command(
      *info, context,
      {[&context, name] { return node_info_json(context.source, *name); }, node_info_table});
}

}  // namespace agnocast::cli
