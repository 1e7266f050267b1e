#include "sweeper.hpp"

#include <spdlog/spdlog.h>

#include <exception>

#include "agnocast/naming.hpp"

namespace agnocastd {

std::vector<std::string> stale_queues(const std::vector<std::string>& listed_files,
                                      const std::set<std::string>& live_queues) {
  std::vector<std::string> stale;
  for (const auto& file : listed_files) {
    if (!agnocast::parse_queue_name(file)) continue;
    const std::string name = "/" + file;
    if (!live_queues.contains(name)) stale.push_back(name);
  }
  return stale;
}

void sweep(Host& host, Counters& counters) {
  const auto listed = host.queue_files();
  std::set<std::string> live;
  try {
    live = host.live_queues();
  } catch (const std::exception& error) {
    spdlog::error("sweep skipped: cannot read the live subscribers: {}", error.what());
    return;
  }
  for (const auto& queue : stale_queues(listed, live)) {
    if (host.remove_queue(queue)) {
      ++counters.queues_removed;
      spdlog::info("removed stale queue {} (no live subscriber owns it)", queue);
    }
  }
  for (const pid_t pid : host.delay_record_pids()) {
    if (host.remove_stale_delay_record(pid, false)) {
      spdlog::info("removed the delay record of dead process {}", pid);
    }
  }
}

}  // namespace agnocastd
