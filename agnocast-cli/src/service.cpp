// agnocast-cli service list | info NAME | type NAME: services seen through the
// two topics that carry each one (<agnocast/naming.hpp>), read like any topic.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <map>
#include <utility>

#include "agnocast/naming.hpp"
#include "commands.hpp"
#include "service_call.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

// One service's endpoints; either topic may be missing while a server or
// client is being created or torn down.
struct ServiceTopics {
  std::optional<TopicInfo> request;  // clients publish, the server subscribes
  std::optional<TopicInfo> reply;    // the server publishes, clients subscribe
};

// A client is a request publisher and a reply subscriber; either may be
// missing for a moment (the reply subscriber is created first).
struct Client {
  pid_t pid = 0;
  std::string node;
  uid_t uid = 0;
  const PublisherInfo* request = nullptr;
  const SubscriberInfo* reply = nullptr;
};

json type_of(const ServiceTopics& service) {
  for (const auto& [topic, role] : {std::pair{&service.request, ServiceTopicRole::request},
                                    std::pair{&service.reply, ServiceTopicRole::reply}}) {
    if (!*topic) continue;
    if (std::string type = service_type_of((*topic)->type_name, role); !type.empty()) return type;
  }
  return nullptr;
}

// One server per service; should the kernel list more request subscribers
// (one going, one coming), the oldest is the server.
const SubscriberInfo* server_of(const ServiceTopics& service) {
  if (!service.request || service.request->subscribers.empty()) return nullptr;
  return &*std::min_element(service.request->subscribers.begin(),
                            service.request->subscribers.end(),
                            [](const auto& a, const auto& b) { return a.id < b.id; });
}

// A client's two endpoints carry its pid and node label, and a node may have
// several clients of one service: within one (pid, node) the k-th request
// publisher and the k-th reply subscriber, in id order, are one client's.
std::vector<Client> clients_of(const ServiceTopics& service) {
  using Key = std::pair<pid_t, std::string>;
  std::map<Key, std::vector<const PublisherInfo*>> requests;
  std::map<Key, std::vector<const SubscriberInfo*>> replies;
  std::map<Key, uid_t> uids;
  if (service.request) {
    for (const PublisherInfo& p : service.request->publishers) {
      requests[{p.pid, p.node}].push_back(&p);
      uids[{p.pid, p.node}] = p.uid;
    }
  }
  if (service.reply) {
    for (const SubscriberInfo& s : service.reply->subscribers) {
      replies[{s.pid, s.node}].push_back(&s);
      uids[{s.pid, s.node}] = s.uid;
    }
  }
  const auto by_id = [](const auto* a, const auto* b) { return a->id < b->id; };
  std::vector<Client> clients;
  for (const auto& [key, uid] : uids) {
    std::vector<const PublisherInfo*>& publishers = requests[key];
    std::vector<const SubscriberInfo*>& subscribers = replies[key];
    std::sort(publishers.begin(), publishers.end(), by_id);
    std::sort(subscribers.begin(), subscribers.end(), by_id);
    for (std::size_t i = 0; i < std::max(publishers.size(), subscribers.size()); ++i) {
      clients.push_back({key.first, key.second, uid,
                         i < publishers.size() ? publishers[i] : nullptr,
                         i < subscribers.size() ? subscribers[i] : nullptr});
    }
  }
  // Oldest first: by the id of the client's first endpoint.
  const auto first_id = [](const Client& c) { return c.reply ? c.reply->id : c.request->id; };
  std::stable_sort(clients.begin(), clients.end(),
                   [&](const Client& a, const Client& b) { return first_id(a) < first_id(b); });
  return clients;
}

// Every service that has an endpoint, by name.
std::map<std::string, ServiceTopics> all_services(InspectionSource& source) {
  std::map<std::string, ServiceTopics> services;
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<ServiceTopic> carried = service_of_topic(summary.name);
    if (!carried) continue;
    std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    ServiceTopics& service = services[carried->service];
    (carried->role == ServiceTopicRole::request ? service.request : service.reply) =
        std::move(info);
  }
  return services;
}

// The service's endpoints; throws CliError when it has none.
ServiceTopics require_service(InspectionSource& source, const std::string& name) {
  ServiceTopics service{source.topic_info(service_request_topic(name)),
                        source.topic_info(service_reply_topic(name))};
  if (!service.request && !service.reply) {
    throw CliError("no server or client uses service '" + name +
                   "'; `agnocast-cli service list` shows the services that exist");
  }
  return service;
}

json client_json(const Client& client) {
  const json calls = client.request ? json(client.request->published) : json(nullptr);
  const json answered =
      client.reply ? json(client.reply->received + client.reply->unreceived) : json(nullptr);
  json in_flight = nullptr;
  if (client.request && client.reply) {
    const std::uint64_t sent = calls.get<std::uint64_t>();
    const std::uint64_t back = answered.get<std::uint64_t>();
    in_flight = sent > back ? sent - back : 0;
  }
  return {{"pid", client.pid},
          {"node", client.node},
          {"uid", client.uid},
          {"request_publisher_id", client.request ? json(client.request->id) : json(nullptr)},
          {"reply_subscriber_id", client.reply ? json(client.reply->id) : json(nullptr)},
          {"calls", calls},
          {"answered", answered},
          {"in_flight", in_flight}};
}

// The sum of one number over the clients that have it.
std::uint64_t total(const json& clients, const char* key) {
  std::uint64_t sum = 0;
  for (const json& client : clients) {
    if (!client.at(key).is_null()) sum += client.at(key).get<std::uint64_t>();
  }
  return sum;
}

const CLI::Validator service_name_validator(
    [](std::string& service) { return service_name_problem(service); }, "NAME", "service name");

}  // namespace

std::string service_type_of(const std::string& topic_type, ServiceTopicRole role) {
  const std::string_view suffix = role == ServiceTopicRole::request ? "_Request" : "_Response";
  if (topic_type.size() <= suffix.size() || !topic_type.ends_with(suffix)) return {};
  return topic_type.substr(0, topic_type.size() - suffix.size());
}

bool is_server_endpoint(ServiceTopicRole role, bool publisher) {
  return (role == ServiceTopicRole::request) != publisher;
}

std::string service_topic_refusal(const std::string& topic) {
  const std::optional<ServiceTopic> carried = service_of_topic(topic);
  if (!carried) return {};
  return "topic '" + topic + "' carries the " +
         (carried->role == ServiceTopicRole::request ? "requests" : "responses") + " of service '" +
         carried->service + "'; `agnocast-cli service info " + carried->service +
         "` shows its server and clients";
}

json service_list_json(InspectionSource& source) {
  json list = json::array();
  for (const auto& [name, service] : all_services(source)) {
    const SubscriberInfo* server = server_of(service);
    list.push_back({{"name", name},
                    {"type", type_of(service)},
                    {"server", server ? json(server->pid) : json(nullptr)},
                    {"clients", clients_of(service).size()}});
  }
  return {{"services", list}};
}

json service_info_json(InspectionSource& source, const std::string& name) {
  const ServiceTopics service = require_service(source, name);
  const SubscriberInfo* server = server_of(service);
  json clients = json::array();
  for (const Client& client : clients_of(service)) clients.push_back(client_json(client));
  return {{"name", name},
          {"type", type_of(service)},
          {"request_topic", service_request_topic(name)},
          {"reply_topic", service_reply_topic(name)},
          {"server", server ? json{{"pid", server->pid},
                                   {"node", server->node},
                                   {"uid", server->uid},
                                   {"request_subscriber_id", server->id}}
                            : json(nullptr)},
          {"clients", clients},
          {"calls", total(clients, "calls")},
          {"answered", total(clients, "answered")},
          {"in_flight", total(clients, "in_flight")},
          {"failures", server ? json(server->dropped) : json(nullptr)}};
}

json service_type_json(InspectionSource& source, const std::string& name) {
  return {{"name", name}, {"type", type_of(require_service(source, name))}};
}

std::string service_list_table(const json& value) {
  Table table({{"NAME"}, {"TYPE"}, {"SERVER", Align::right}, {"CLIENTS", Align::right}});
  for (const json& s : value.at("services")) {
    table.add_row(
        {cell(s.at("name")), cell(s.at("type")), cell(s.at("server")), cell(s.at("clients"))});
  }
  return table.render();
}

std::string service_info_table(const json& value) {
  const json& server = value.at("server");
  json lines = value;
  lines["service"] = value.at("name");
  lines["server"] = server.is_null()
                        ? json(nullptr)
                        : json(cell(server.at("pid")) + " (node " + cell(server.at("node")) + ")");
  Table clients({{"PID", Align::right},
                 {"UID", Align::right},
                 {"NODE"},
                 {"CALLS", Align::right},
                 {"ANSWERED", Align::right},
                 {"IN_FLIGHT", Align::right}});
  for (const json& c : value.at("clients")) {
    clients.add_row({cell(c.at("pid")), cell(c.at("uid")), cell(c.at("node")), cell(c.at("calls")),
                     cell(c.at("answered")), cell(c.at("in_flight"))});
  }
  return key_value_lines(
             lines, {"service", "type", "server", "calls", "answered", "in_flight", "failures"}) +
         "\nclients\n" + clients.render();
}

std::string service_type_table(const json& value) { return cell(value.at("type")) + "\n"; }

void set_service_command(CLI::App& app, Context& context) {
  CLI::App* service = app.add_subcommand("service", "Services: their server, clients and calls");
  service->require_subcommand(1);

  CLI::App* list = service->add_subcommand("list", "Every service with its server and clients");
  bind_command(*list, context,
               {[&context] { return service_list_json(context.source); }, service_list_table});

  auto name = std::make_shared<std::string>();
  CLI::App* info = service->add_subcommand(
      "info", "The server and clients of one service, with calls in flight and failures");
  info->add_option("NAME", *name, "Service name, e.g. /arm/enable")
      ->required()
      ->check(service_name_validator);
  bind_command(
      *info, context,
      {[&context, name] { return service_info_json(context.source, *name); }, service_info_table});

  CLI::App* type = service->add_subcommand("type", "The type of one service");
  type->add_option("NAME", *name, "Service name, e.g. /arm/enable")
      ->required()
      ->check(service_name_validator);
  bind_command(
      *type, context,
      {[&context, name] { return service_type_json(context.source, *name); }, service_type_table});

  set_service_call_command(*service, context);
}

}  // namespace agnocast::cli
