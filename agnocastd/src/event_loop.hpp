// The serve loop: one poll over the exit records, the stop signals, the sweep
// timer and the watchdog timer.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include "agnocast/supervise.hpp"
#include "cleaner.hpp"
#include "config.hpp"
#include "counters.hpp"
#include "host.hpp"

namespace agnocastd {

// What the daemon knows while it serves.
struct Supervisor {
  Supervisor(const Config& config, Host& host, agnocast::ExitRecordReader& exit_records,
             std::string status_path, std::string module_version)
      : config(config),
        host(host),
        exit_records(exit_records),
        status_path(std::move(status_path)),
        module_version(std::move(module_version)) {}

  const Config& config;
  Host& host;
  agnocast::ExitRecordReader& exit_records;
  std::string status_path;
  std::string module_version;
  DeadProcessCollector collector;
  Counters counters;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::chrono::system_clock::time_point started_at = std::chrono::system_clock::now();
};

// Blocks SIGTERM, SIGINT and SIGHUP so that they queue for serve()'s signalfd
// even while the daemon is still starting.
void block_daemon_signals();

// Cleans up after every process whose exit records wait now.
void clean_exited_processes(Supervisor& supervisor);

// Rewrites the status file; logs (does not throw) when it cannot.
void write_status(const Supervisor& supervisor, bool running);

// True when /dev/agnocast is there and answers with a compatible version.
bool module_healthy();

// Serves until SIGTERM or SIGINT (SIGHUP sweeps at once). Throws on a broken
// descriptor.
void serve(Supervisor& supervisor);

}  // namespace agnocastd
