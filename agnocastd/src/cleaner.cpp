#include "cleaner.hpp"

#include <spdlog/spdlog.h>

#include <utility>

#include "sweeper.hpp"

namespace agnocastd {

std::vector<DeadProcess> DeadProcessCollector::add(
    const std::vector<agnocast::ExitRecord>& records) {
  std::vector<DeadProcess> dead;
  for (const auto& record : records) {
    if (record.kind == agnocast::ExitRecord::Kind::lost) {
      lost_ += record.lost_count;
      // Their process records may be among the lost ones; the sweep that
      // follows removes these queues as no live subscriber owns them.
      pending_queues_.clear();
      continue;
    }
    if (record.kind == agnocast::ExitRecord::Kind::queue) {
      pending_queues_[record.pid].push_back(record.queue());
      continue;
    }
    DeadProcess process{record.pid, {}};
    if (const auto pending = pending_queues_.find(record.pid); pending != pending_queues_.end()) {
      process.queues = std::move(pending->second);
      pending_queues_.erase(pending);
    }
    dead.push_back(std::move(process));
  }
  return dead;
}

std::uint64_t DeadProcessCollector::take_lost() { return std::exchange(lost_, 0); }

void clean_dead_process(const DeadProcess& process, Host& host, Counters& counters) {
  for (const auto& queue : process.queues) {
    if (host.remove_queue(queue)) {
      ++counters.queues_removed;
      spdlog::info("removed queue {} of dead process {}", queue, process.pid);
    }
  }
  if (host.remove_stale_delay_record(process.pid, true)) {
    spdlog::info("removed the delay record of dead process {}", process.pid);
  }
  ++counters.processes_cleaned;
  spdlog::info("cleaned up after dead process {} ({} queue(s))", process.pid,
               process.queues.size());
}

bool handle_exit_records(const std::vector<agnocast::ExitRecord>& records,
                         DeadProcessCollector& collector, Host& host, Counters& counters) {
  bool cleaned = false;
  for (const auto& process : collector.add(records)) {
    clean_dead_process(process, host, counters);
    cleaned = true;
  }
  if (const std::uint64_t lost = collector.take_lost(); lost > 0) {
    spdlog::warn("the kernel discarded {} exit record(s) unread; sweeping now", lost);
    sweep(host, counters);
    cleaned = true;
  }
  return cleaned;
}

}  // namespace agnocastd
