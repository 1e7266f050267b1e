// agnocastd's status file: where it is and what it says, for the daemon that
// writes it and the tools that read it without privileges (agnocast-cli).
//
// The file is one JSON object, replaced atomically (rename), mode 0644:
//   {"running":true,"pid":123,"module_loaded":true,"module_version":"0.1.0",
//    "uptime_s":42,"started_at":1700000000,"processes_cleaned":0,
//    "queues_removed":0,"shm_removed":0}
// uptime_s is as of the last write (at least every sweep interval and after
// every cleanup); started_at (Unix seconds) gives the exact uptime. On a clean
// stop the file is rewritten with "running":false. After a crash it may still
// say running:true: a reader confirms with the lock file beside it, which the
// daemon holds with flock(LOCK_EX) while it runs (a non-blocking
// flock(LOCK_SH) on a read-only descriptor fails with EWOULDBLOCK then) and
// which holds its pid.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "agnocast/errors.hpp"

namespace agnocast {

// The directory of the daemons' runtime files (mode 0755).
inline constexpr std::string_view runtime_directory = "/run/agnocast";
inline constexpr std::string_view daemon_status_path = "/run/agnocast/agnocastd.json";
inline constexpr std::string_view daemon_lock_path = "/run/agnocast/agnocastd.lock";

// The lock file that goes with a status file: the daemon's lock's name in the
// status file's directory, so an overridden status path finds its own lock.
std::string daemon_lock_path_beside(std::string_view status_path);

// What agnocastd has removed since it started.
struct DaemonCounters {
  std::uint64_t processes_cleaned = 0;
  std::uint64_t queues_removed = 0;
  std::uint64_t shm_removed = 0;

  bool operator==(const DaemonCounters&) const = default;
};

struct DaemonStatus {
  bool running = true;
  pid_t pid = 0;
  std::optional<std::string> module_version;  // nullopt: module not loaded
  std::uint64_t uptime_s = 0;
  std::int64_t started_at = 0;  // Unix seconds
  DaemonCounters counters;

  bool operator==(const DaemonStatus&) const = default;
};

// A status file that is not JSON, or lacks a field or has one of another
// type; what() names the field and what it should be.
class StatusFormatError : public Error {
 public:
  using Error::Error;
};

// The file's text: one JSON object and a newline.
std::string to_json(const DaemonStatus& status);
// Throws StatusFormatError.
DaemonStatus daemon_status_from_json(std::string_view text);

}  // namespace agnocast
