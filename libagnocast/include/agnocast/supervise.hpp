// Daemon-side API (agnocastd): the stream of exit records the module queues
// when a registered process dies, so the daemon can remove what it left behind.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "agnocast/naming.hpp"
#include "agnocast/version.hpp"

namespace agnocast {

struct ExitRecord {
  enum class Kind {
    process,  // the process died; every record about it came before
    queue,    // a callback subscriber of the dead process owned this queue
    lost,     // lost_count older records were discarded unread: look for leftovers
  };
  Kind kind = Kind::process;
  pid_t pid = 0;
  std::string topic;                // queue records only
  std::uint32_t subscriber_id = 0;  // queue records only
  std::uint32_t lost_count = 0;     // lost records only

  // The notification queue a queue record names, e.g. "/chatter@1".
  std::string queue() const { return queue_name(topic, subscriber_id); }
};

// Reads exit records from /dev/agnocast without registering the process.
// Reading needs CAP_SYS_ADMIN (DeviceError with code EPERM otherwise).
class ExitRecordReader {
 public:
  ExitRecordReader();  // throws ModuleNotLoaded
  ~ExitRecordReader();
  ExitRecordReader(const ExitRecordReader&) = delete;
  ExitRecordReader& operator=(const ExitRecordReader&) = delete;

  // Non-blocking descriptor; poll() it for POLLIN.
  int fd() const { return fd_; }
  // Every record waiting now, oldest first; empty when none waits.
  std::vector<ExitRecord> read_available();

 private:
  int fd_;
};

}  // namespace agnocast
