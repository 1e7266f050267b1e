// The operating-system work of cleaning up, behind an interface so the
// cleaner's and the sweeper's decisions are unit-tested with a fake.
#pragma once

#include <sys/types.h>

#include <set>
#include <string>
#include <vector>

namespace agnocastd {

class Host {
 public:
  virtual ~Host() = default;
  // File names in the mqueue filesystem, e.g. "chatter@1".
  virtual std::vector<std::string> queue_files() = 0;
  // Queue names ("/chatter@1") of the callback subscribers the kernel lists now.
  virtual std::set<std::string> live_queues() = 0;
  // mq_unlink(name); false when it did not exist (or could not be removed, logged).
  virtual bool remove_queue(const std::string& name) = 0;
  // The pids of the delay records in /dev/shm (agnocast::delay_record_pids).
  virtual std::vector<pid_t> delay_record_pids() = 0;
  // agnocast::remove_stale_delay_record: true when pid's record was removed.
  virtual bool remove_stale_delay_record(pid_t pid, bool exit_reported) = 0;
};

// The Host of this machine: /dev/mqueue and the kernel module.
class SystemHost final : public Host {
 public:
  std::vector<std::string> queue_files() override;
  std::set<std::string> live_queues() override;
  bool remove_queue(const std::string& name) override;
  std::vector<pid_t> delay_record_pids() override;
  bool remove_stale_delay_record(pid_t pid, bool exit_reported) override;
};

}  // namespace agnocastd
