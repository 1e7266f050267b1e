// Where agnocastd publishes its state for tools that run without privileges
// (agnocast-cli daemon status). Header-only: CMake target agnocastd_status.
//
// The status file is one JSON object, replaced atomically (rename), mode 0644:
//   {"running":true,"pid":123,"module_loaded":true,"module_version":"0.1.0",
//    "uptime_s":42,"started_at":1700000000,"processes_cleaned":0,
//    "queues_removed":0,"shm_removed":0}
// uptime_s is as of the last write (at least every sweep interval and after
// every cleanup); started_at (Unix seconds) gives the exact uptime. On a clean
// stop the file is rewritten with "running":false. After a crash it may still
// say running:true: a reader confirms with the lock file, which the daemon
// holds with flock(LOCK_EX) while it runs (a non-blocking flock(LOCK_SH) on a
// read-only descriptor fails with EWOULDBLOCK then) and which holds its pid.
#pragma once

#include <string_view>

namespace agnocastd {

inline constexpr std::string_view runtime_directory = "/run/agnocast";
inline constexpr std::string_view status_path = "/run/agnocast/agnocastd.json";
inline constexpr std::string_view lock_path = "/run/agnocast/agnocastd.lock";

}  // namespace agnocastd
