// agnocast-cli node list | info NODE: endpoints grouped by process and node
// label; those on the topics that carry a service count as serving or calling it.
#include <CLI/CLI.hpp>
#include <map>
#include <set>
#include <utility>

#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

struct Endpoints {
  std::set<std::string> publishes;
  std::set<std::string> subscribes;
  std::set<std::string> serves;  // services, from the topics that carry them
  std::set<std::string> calls;
};

// Where an endpoint of a node goes: its topic, or the service the topic carries.
void add_endpoint(Endpoints& endpoints, const std::string& topic, bool publisher) {
  if (const std::optional<ServiceTopic> carried = service_of_topic(topic)) {
    (is_server_endpoint(carried->role, publisher) ? endpoints.serves : endpoints.calls)
        .insert(carried->service);
    return;
  }
  (publisher ? endpoints.publishes : endpoints.subscribes).insert(topic);
}

}  // namespace

json node_list_json(InspectionSource& source) {
  // Ordered by pid, then label: a node is a label within one process.
  std::map<std::pair<pid_t, std::string>, Endpoints> nodes;
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const PublisherInfo& p : info->publishers) {
      add_endpoint(nodes[{p.pid, p.node}], info->name, true);
    }
    for (const SubscriberInfo& s : info->subscribers) {
      add_endpoint(nodes[{s.pid, s.node}], info->name, false);
    }
  }
  json list = json::array();
  for (const auto& [key, endpoints] : nodes) {
    list.push_back({{"name", key.second},
                    {"pid", key.first},
                    {"publishes", endpoints.publishes},
                    {"subscribes", endpoints.subscribes},
                    {"serves", endpoints.serves},
                    {"calls", endpoints.calls}});
  }
  return {{"nodes", list}};
}

json node_info_json(InspectionSource& source, const std::string& node) {
  std::set<pid_t> pids;
  // name -> type, per direction; a node using a topic from two pids lists it once.
  std::map<std::string, std::string> publishes;
  std::map<std::string, std::string> subscribes;
  std::map<std::string, std::string> serves;
  std::map<std::string, std::string> calls;
  const auto add = [&](const TopicInfo& topic, bool publisher) {
    if (const std::optional<ServiceTopic> carried = service_of_topic(topic.name)) {
      std::string& type =
          (is_server_endpoint(carried->role, publisher) ? serves : calls)[carried->service];
      if (type.empty()) type = service_type_of(topic.type_name, carried->role);
      return;
    }
    (publisher ? publishes : subscribes)[topic.name] = topic.type_name;
  };
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const PublisherInfo& p : info->publishers) {
      if (p.node != node) continue;
      pids.insert(p.pid);
      add(*info, true);
    }
    for (const SubscriberInfo& s : info->subscribers) {
      if (s.node != node) continue;
      pids.insert(s.pid);
      add(*info, false);
    }
  }
  if (pids.empty()) {
    throw CliError("no endpoint belongs to node '" + node +
                   "'; `agnocast-cli node list` shows the nodes that exist");
  }
  const auto endpoints = [](const std::map<std::string, std::string>& names, const char* kind) {
    json list = json::array();
    for (const auto& [name, type] : names) {
      list.push_back({{kind, name}, {"type", type.empty() ? json(nullptr) : json(type)}});
    }
    return list;
  };
  return {{"name", node},
          {"pids", pids},
          {"publishers", endpoints(publishes, "topic")},
          {"subscribers", endpoints(subscribes, "topic")},
          {"servers", endpoints(serves, "service")},
          {"clients", endpoints(calls, "service")}};
}

std::string node_info_table(const json& value) {
  Table endpoints({{"DIRECTION"}, {"TOPIC"}, {"TYPE"}});
  for (const char* direction : {"publishers", "subscribers"}) {
    for (const json& e : value.at(direction)) {
      endpoints.add_row({direction == std::string("publishers") ? "publishes" : "subscribes",
                         cell(e.at("topic")), cell(e.at("type"))});
    }
  }
  std::string text = "node " + cell(value.at("name")) + "\npids " + cell(value.at("pids")) +
                     "\n\n" + endpoints.render();
  if (value.at("servers").empty() && value.at("clients").empty()) return text;
  Table services({{"ROLE"}, {"SERVICE"}, {"TYPE"}});
  for (const char* role : {"servers", "clients"}) {
    for (const json& e : value.at(role)) {
      services.add_row({role == std::string("servers") ? "serves" : "calls", cell(e.at("service")),
                        cell(e.at("type"))});
    }
  }
  return text + "\n" + services.render();
}

std::string node_list_table(const json& value) {
  Table table(
      {{"NAME"}, {"PID", Align::right}, {"PUBLISHES"}, {"SUBSCRIBES"}, {"SERVES"}, {"CALLS"}});
  for (const json& n : value.at("nodes")) {
    table.add_row({cell(n.at("name")), cell(n.at("pid")), cell(n.at("publishes")),
                   cell(n.at("subscribes")), cell(n.at("serves")), cell(n.at("calls"))});
  }
  return table.render();
}

void set_node_command(CLI::App& app, Context& context) {
  CLI::App* node = app.add_subcommand("node", "Nodes: the labelled endpoints of each process");
  node->require_subcommand(1);
  CLI::App* list = node->add_subcommand("list", "Every node with the topics and services it uses");
  bind_command(*list, context,
               {[&context] { return node_list_json(context.source); }, node_list_table});
  auto name = std::make_shared<std::string>();
  CLI::App* info = node->add_subcommand("info", "The processes, topics and services of one node");
  info->add_option("NODE", *name, "Node name, e.g. talker")->required();
  bind_command(
      *info, context,
      {[&context, name] { return node_info_json(context.source, *name); }, node_info_table});
}

}  // namespace agnocast::cli
