// An in-memory Host for the cleaner and sweeper tests.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "host.hpp"

namespace agnocastd {

class FakeHost final : public Host {
 public:
  std::set<std::string> queues;  // file names in /dev/mqueue, "x@1"
  std::set<std::string> live;    // queue names, "/x@1"
  bool kernel_unreachable = false;
  std::set<pid_t> delay_records;  // pids with a record in /dev/shm
  std::set<pid_t> live_pids;      // whose records are their own
  // remove_stale_delay_record's arguments: pid, exit_reported.
  std::vector<std::pair<pid_t, bool>> delay_record_checks;
  std::vector<std::string> calls;               // the order of OS work, for order checks
  std::function<void()> between_list_and_live;  // runs after queue_files()

  std::vector<std::string> queue_files() override {
    calls.push_back("queue_files");
    std::vector<std::string> listed(queues.begin(), queues.end());
    if (between_list_and_live) between_list_and_live();
    return listed;
  }
  std::set<std::string> live_queues() override {
    calls.push_back("live_queues");
    if (kernel_unreachable) throw std::runtime_error("/dev/agnocast is gone");
    return live;
  }
  bool remove_queue(const std::string& name) override {
    calls.push_back("remove_queue " + name);
    return queues.erase(name.substr(1)) > 0;
  }
  std::vector<pid_t> delay_record_pids() override {
    return std::vector<pid_t>(delay_records.begin(), delay_records.end());
  }
  bool remove_stale_delay_record(pid_t pid, bool exit_reported) override {
    delay_record_checks.push_back({pid, exit_reported});
    return !live_pids.contains(pid) && delay_records.erase(pid) > 0;
  }
};

}  // namespace agnocastd
