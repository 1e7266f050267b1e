#include "host.hpp"

#include <dirent.h>
#include <mqueue.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include "agnocast/inspect.hpp"
#include "agnocast/naming.hpp"

namespace agnocastd {
namespace {

std::vector<std::string> list_directory(const std::string& path) {
  std::vector<std::string> names;
  const std::unique_ptr<DIR, int (*)(DIR*)> dir(::opendir(path.c_str()), ::closedir);
  if (!dir) {
    spdlog::warn("cannot list {}: {}", path, std::strerror(errno));
    return names;
  }
  while (const dirent* entry = ::readdir(dir.get())) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  return names;
}

bool removed(int result, const std::string& what) {
  if (result == 0) return true;
  if (errno != ENOENT) spdlog::warn("cannot remove {}: {}", what, std::strerror(errno));
  return false;
}

}  // namespace

std::vector<std::string> SystemHost::queue_files() {
  return list_directory(std::string(agnocast::mqueue_directory));
}

std::set<std::string> SystemHost::live_queues() {
  std::set<std::string> queues;
  for (const auto& [queue, owner] : agnocast::live_queue_owners()) queues.insert(queue);
  return queues;
}

bool SystemHost::remove_queue(const std::string& name) {
  return removed(::mq_unlink(name.c_str()), "queue " + name);
}

std::vector<pid_t> SystemHost::delay_record_pids() { return agnocast::delay_record_pids(); }

bool SystemHost::remove_stale_delay_record(pid_t pid, bool exit_reported) {
  return agnocast::remove_stale_delay_record(pid, exit_reported);
}

}  // namespace agnocastd
