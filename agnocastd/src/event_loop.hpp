// The serve loop: one poll over the exit records, the stop signals, the sweep
// timer and the watchdog timer.
#pragma once

#include <chrono>
#include <functional>
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
  Supervisor(Config config, std::function<Config()> reread_config, Host& host,
             agnocast::ExitRecordReader& exit_records, std::string status_path,
             std::string module_version)
      : config(std::move(config)),
        reread_config(std::move(reread_config)),
        host(host),
        exit_records(exit_records),
        status_path(std::move(status_path)),
        module_version(std::move(module_version)) {}

  Config config;  // the one in force; SIGHUP replaces it
  // Reads the configuration file again; throws ConfigError.
  std::function<Config()> reread_config;
  Host& host;
  agnocast::ExitRecordReader& exit_records;
  std::string status_path;
  std::string module_version;
  DeadProcessCollector collector;
  Counters counters;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::chrono::system_clock::time_point started_at = std::chrono::system_clock::now();
};

// Cleans up after every process whose exit records wait now; sweeps when
// the kernel discarded records unread.
void clean_exited_processes(Supervisor& supervisor);

// Re-reads the configuration and applies it (see reload.hpp); a bad file or a
// failure to apply it is logged and the configuration in force stays. True
// when the new configuration is in force.
bool reload_config(Supervisor& supervisor);

// Rewrites the status file; logs (does not throw) when it cannot.
void write_status(const Supervisor& supervisor, bool running);

// True when /dev/agnocast is there and answers with a compatible version.
bool module_healthy();

// Serves until SIGTERM or SIGINT; SIGHUP reloads the configuration, then
// sweeps. Throws on a broken descriptor.
void serve(Supervisor& supervisor);

}  // namespace agnocastd
