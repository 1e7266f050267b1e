// agnocast-cli process list: every process registered with the module, its
// nodes and its pool. The kernel knows the pool's place and size and the
// messages it keeps there for subscribers (each publisher's depth window);
// how much of the pool is in use is what the process has touched of it, the
// pool mapping's resident size in /proc/PID/smaps (null where /proc does not
// tell this user).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;
using Align = Table::Align;

// The effective uid from /proc/PID/status, null when it cannot be read.
json uid_of(InspectionSource& source, pid_t pid) {
  const auto status = source.read_file("/proc/" + std::to_string(pid) + "/status");
  if (!status) return nullptr;
  std::istringstream lines(*status);
  std::string line;
  while (std::getline(lines, line)) {
    unsigned long real = 0;
    unsigned long effective = 0;
    if (std::sscanf(line.c_str(), "Uid: %lu %lu", &real, &effective) == 2) return effective;
  }
  return nullptr;
}

// Resident bytes of the mapping that starts at `address`, from /proc/PID/smaps.
json resident_bytes(InspectionSource& source, pid_t pid, std::uint64_t address) {
  const auto smaps = source.read_file("/proc/" + std::to_string(pid) + "/smaps");
  if (!smaps) return nullptr;
  std::istringstream lines(*smaps);
  std::string line;
  bool in_pool = false;
  while (std::getline(lines, line)) {
    unsigned long long start = 0;
    unsigned long long end = 0;
    if (std::sscanf(line.c_str(), "%llx-%llx ", &start, &end) == 2) {
      in_pool = start == address;
      continue;
    }
    unsigned long long kilobytes = 0;
    if (in_pool && std::sscanf(line.c_str(), "Rss: %llu kB", &kilobytes) == 1) {
      return kilobytes * 1024;
    }
  }
  return nullptr;
}

}  // namespace

json process_list_json(InspectionSource& source) {
  std::map<pid_t, std::set<std::string>> nodes;
  std::map<pid_t, std::uint64_t> messages;
  for (const TopicSummary& summary : source.list_topics()) {
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;  // the topic went away since it was listed
    for (const PublisherInfo& p : info->publishers) {
      nodes[p.pid].insert(p.node);
      messages[p.pid] += p.window;
    }
    for (const SubscriberInfo& s : info->subscribers) nodes[s.pid].insert(s.node);
  }
  std::vector<ProcessInfo> processes = source.list_processes();
  std::sort(processes.begin(), processes.end(),
            [](const auto& a, const auto& b) { return a.pid < b.pid; });
  json list = json::array();
  for (const ProcessInfo& process : processes) {
    // A process that never published has no pool.
    const json pool = process.pool_size == 0
                          ? json(nullptr)
                          : json{{"size", process.pool_size},
                                 {"used", resident_bytes(source, process.pid, process.pool_addr)},
                                 {"messages", messages[process.pid]}};
    list.push_back({{"pid", process.pid},
                    {"uid", uid_of(source, process.pid)},
                    {"nodes", nodes[process.pid]},
                    {"publishers", process.publishers},
                    {"subscribers", process.subscribers},
                    {"pool", pool}});
  }
  return {{"processes", list}};
}

std::string process_list_table(const json& value) {
  Table table({{"PID", Align::right},
               {"UID", Align::right},
               {"NODES"},
               {"PUBLISHERS", Align::right},
               {"SUBSCRIBERS", Align::right},
               {"POOL_SIZE", Align::right},
               {"POOL_USED", Align::right},
               {"MESSAGES", Align::right}});
  for (const json& p : value.at("processes")) {
    const json& pool = p.at("pool");
    const auto pool_cell = [&pool](const char* key) {
      return pool.is_null() ? std::string("-") : cell(pool.at(key));
    };
    table.add_row({cell(p.at("pid")), cell(p.at("uid")), cell(p.at("nodes")),
                   cell(p.at("publishers")), cell(p.at("subscribers")), pool_cell("size"),
                   pool_cell("used"), pool_cell("messages")});
  }
  return table.render();
}

void set_process_command(CLI::App& app, Context& context) {
  CLI::App* process =
      app.add_subcommand("process", "Processes registered with the module and their pools");
  process->require_subcommand(1);
  CLI::App* list = process->add_subcommand(
      "list", "Every process with its nodes, endpoint counts and pool usage");
  bind_command(*list, context,
               {[&context] { return process_list_json(context.source); }, process_list_table});
}

}  // namespace agnocast::cli
