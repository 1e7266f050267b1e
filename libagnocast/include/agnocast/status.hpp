// The daemons' status files: where they are and what they say, for the
// daemons that write them (through the service kit, service/) and the tools
// that read them without privileges (agnocast-cli daemon status).
//
// Each file is one JSON object, replaced atomically (rename), mode 0644. It
// starts with a head every daemon writes (ServiceStatus):
//   {"program":"agnocastd","pid":123,"version":"0.1.0","state":"running",
//    "running":true,"started_at":1700000000,"uptime_s":42,"written_at":1700000042,
// and goes on with the daemon's own fields; agnocastd's (DaemonStatus):
//    "module_loaded":true,"module_version":"0.1.0","processes_cleaned":0,
//    "queues_removed":0,"shm_removed":0}
// (DaemonStatus restates running, pid, uptime_s and started_at, which it had
// before the head; they are the head's values.)
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
inline constexpr std::string_view bridge_status_path = "/run/agnocast/bridge.json";
inline constexpr std::string_view foxglove_status_path = "/run/agnocast/foxglove.json";

// The lock file that goes with a status file: the daemon's lock's name in the
// status file's directory, so an overridden status path finds its own lock.
std::string daemon_lock_path_beside(std::string_view status_path);
// The lock file a daemon holds while it writes status_path: the same name
// with ".lock" for its extension ("/run/agnocast/bridge.json" ->
// "/run/agnocast/bridge.lock").
std::string lock_path_beside(std::string_view status_path);

// running: serving; stopping: asked to stop (STOPPING=1), still finishing its
// work; stopped: the last write of a clean stop, or of a failure.
enum class ServiceState { running, stopping, stopped };

// "running", "stopping", "stopped".
std::string_view state_name(ServiceState state);

// The head of every daemon's status file.
struct ServiceStatus {
  std::string program;  // "agnocastd", "agnocast-bridge", "agnocast-foxglove"
  pid_t pid = 0;
  std::string version;  // the library's version the daemon was built with
  ServiceState state = ServiceState::running;
  std::int64_t started_at = 0;  // Unix seconds
  std::uint64_t uptime_s = 0;   // as of written_at
  std::int64_t written_at = 0;  // Unix seconds

  // "running" in the file: true until the last write.
  bool running() const { return state != ServiceState::stopped; }
  bool operator==(const ServiceStatus&) const = default;
};

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

// The head alone, its fields in the file's order: one JSON object and a newline.
std::string to_json(const ServiceStatus& head);
// The head of any daemon's status file; the fields after it are not read.
// Throws StatusFormatError.
ServiceStatus service_status_from_json(std::string_view text);

}  // namespace agnocast
