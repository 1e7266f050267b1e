// Every subcommand: a set_<cmd>_command() that wires it into CLI11 and pure
// <cmd>_json() functions that build its value from an InspectionSource, plus
// the table renderers of those values. Shapes: agnocast-cli/README.md.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "agnocast/naming.hpp"
#include "agnocast/status.hpp"
#include "cli.hpp"
#include "inspection_source.hpp"
#include "topic_windows.hpp"

namespace agnocast::cli {

void set_topic_command(CLI::App& app, Context& context);
nlohmann::json topic_list_json(InspectionSource& source);
// Throws CliError when no endpoint of the topic exists.
nlohmann::json topic_info_json(InspectionSource& source, const std::string& topic);
// The topic's endpoints; throws CliError when it has none.
TopicInfo require_topic(InspectionSource& source, const std::string& topic);
std::string topic_list_table(const nlohmann::json& value);
std::string topic_info_table(const nlohmann::json& value);

// topic delay TOPIC: per window, each subscriber's delay from publish() to
// its callback's start: min_us, p50_us, p99_us, max_us (null when it timed
// none), messages and missed (null for a subscriber that records none).
using DelayOptions = WindowOptions;
void set_topic_delay_command(CLI::App& topic, Context& context);
int topic_delay(InspectionSource& source, const DelayOptions& options, std::ostream& out);
std::string topic_delay_header();
std::string topic_delay_lines(const nlohmann::json& window);

// topic hz TOPIC: one measurement per window: rate_hz, the period's
// min_s, max_s and std_dev_s (null with fewer than two messages so far) and
// bytes_per_s of payload, until --count windows or a signal.
using HzOptions = WindowOptions;
void set_topic_hz_command(CLI::App& topic, Context& context);
// Writes one line per window to `out`; returns the exit code, throws CliError
// when the topic has no endpoint.
int topic_hz(InspectionSource& source, const HzOptions& options, std::ostream& out);
std::string topic_hz_header();
std::string topic_hz_line(const nlohmann::json& window);

// topic echo TOPIC: subscribes and prints every message decoded from the schema
// its publisher registered, until --count messages, --timeout or a signal.
struct EchoOptions {
  std::string topic;
  std::optional<std::size_t> count;  // stop after this many (exit 0)
  std::optional<double> timeout_s;   // give up (exit 1) when fewer arrived by then
  bool show_arrays = true;
  bool json = false;        // JSON Lines instead of YAML-like text
  bool definition = false;  // print the type's .msg definition instead, and exit
};
// A subcommand of `topic`.
void set_topic_echo_command(CLI::App& topic, Context& context);
// Writes the messages to `out`; returns the exit code, throws CliError on a timeout.
int topic_echo(InspectionSource& source, const EchoOptions& options, std::ostream& out);

// service list | info NAME | type NAME, read from the two topics that carry
// each service. A client is a request publisher and a reply subscriber of one
// (pid, node), paired in id order; its calls are the publisher's published
// count, its answers its reply subscriber's received + unreceived, and the
// difference (never below 0) is in flight. A service's failures are the
// requests its server's request subscriber dropped.
void set_service_command(CLI::App& app, Context& context);
nlohmann::json service_list_json(InspectionSource& source);
// These throw CliError when no endpoint of the service exists.
nlohmann::json service_info_json(InspectionSource& source, const std::string& service);
nlohmann::json service_type_json(InspectionSource& source, const std::string& service);
std::string service_list_table(const nlohmann::json& value);
std::string service_info_table(const nlohmann::json& value);
std::string service_type_table(const nlohmann::json& value);
// "std_srvs/srv/SetBool" from the type of the request topic
// ("std_srvs/srv/SetBool_Request") or of the reply topic ("..._Response");
// empty for a type of neither form.
std::string service_type_of(const std::string& topic_type, ServiceTopicRole role);
// Whether an endpoint on a topic that carries a service is its server's (the
// request subscriber, the reply publisher) rather than a client's.
bool is_server_endpoint(ServiceTopicRole role, bool publisher);
// Why a command that subscribes refuses a topic that carries a service
// (nobody but its server and clients may use it), empty for any other topic.
std::string service_topic_refusal(const std::string& topic);

void set_queue_command(CLI::App& app, Context& context);
nlohmann::json queue_list_json(InspectionSource& source);
std::string queue_list_table(const nlohmann::json& value);

void set_node_command(CLI::App& app, Context& context);
nlohmann::json node_list_json(InspectionSource& source);
std::string node_list_table(const nlohmann::json& value);
// node info NODE: the pids using the label and the topics each direction uses,
// with their types. Throws CliError when no endpoint carries the label.
nlohmann::json node_info_json(InspectionSource& source, const std::string& node);
std::string node_info_table(const nlohmann::json& value);

void set_process_command(CLI::App& app, Context& context);
nlohmann::json process_list_json(InspectionSource& source);
std::string process_list_table(const nlohmann::json& value);

void set_daemon_command(CLI::App& app, Context& context);
// agnocastd's status file as read: no status when it is absent (problem
// empty) or unreadable (problem names the file and what is wrong with it).
struct DaemonStatusRead {
  std::optional<DaemonStatus> status;
  std::string problem;
};
DaemonStatusRead read_daemon_status(InspectionSource& source, const std::string& status_path);
// `status_path` is agnocastd's status file; its lock file sits beside it.
nlohmann::json daemon_status_json(InspectionSource& source, const std::string& status_path);
// Another daemon's status file (agnocast-bridge's, agnocast-foxglove's): the
// file's object with uptime_s as of now while `program` runs (its lock beside
// the file held, see <agnocast/status.hpp>), else
// {"running":false,"pid":null,"uptime_s":null}.
nlohmann::json service_status_json(InspectionSource& source, const std::string& status_path,
                                   const std::string& program);
struct DaemonStatusPaths {
  std::string agnocastd{daemon_status_path};
  std::string bridge{bridge_status_path};
  std::string foxglove{foxglove_status_path};
};
// What `daemon status` prints: daemon_status_json() with "bridge" and
// "foxglove" added, each a service_status_json().
nlohmann::json daemon_status_command_json(InspectionSource& source, const DaemonStatusPaths& paths);
// agnocastd's lines, then a row per other daemon the value has.
std::string daemon_status_table(const nlohmann::json& value);

void set_doctor_command(CLI::App& app, Context& context);
nlohmann::json doctor_json(InspectionSource& source, const std::string& daemon_status_path);
std::string doctor_table(const nlohmann::json& value);

void set_policy_command(CLI::App& app, Context& context);
// {"policy": null} without a policy; principals by name ("group:safety"),
// or by id when the system has no name for it ("user:1234").
nlohmann::json policy_show_json(InspectionSource& source);
std::string policy_show_table(const nlohmann::json& value);

void set_version_command(CLI::App& app, Context& context);
nlohmann::json version_json(InspectionSource& source);
std::string version_table(const nlohmann::json& value);

}  // namespace agnocast::cli
