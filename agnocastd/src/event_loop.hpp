// The serve loop: the service kit's loop (signals, watchdog, status file)
// over the exit records and the sweep timer.
#pragma once

#include <functional>
#include <string>
#include <utility>

#include "agnocast/status.hpp"
#include "agnocast/supervise.hpp"
#include "agnocast_service/service_loop.hpp"
#include "cleaner.hpp"
#include "config.hpp"
#include "counters.hpp"
#include "host.hpp"

namespace agnocastd {

// What the daemon knows while it serves.
struct Supervisor {
  Supervisor(Config config, std::function<Config()> reread_config, Host& host,
             agnocast::ExitRecordReader& exit_records, agnocast_service::ServiceLoop& service,
             std::string module_version)
      : config(std::move(config)),
        reread_config(std::move(reread_config)),
        host(host),
        exit_records(exit_records),
        service(service),
        module_version(std::move(module_version)) {}

  Config config;  // the one in force; SIGHUP replaces it
  // Reads the configuration file again; throws ConfigError.
  std::function<Config()> reread_config;
  Host& host;
  agnocast::ExitRecordReader& exit_records;
  agnocast_service::ServiceLoop& service;  // writes the status file
  std::string module_version;
  DeadProcessCollector collector;
  Counters counters;
};

// Cleans up after every process whose exit records wait now; sweeps when
// the kernel discarded records unread.
void clean_exited_processes(Supervisor& supervisor);

// Re-reads the configuration and applies it (see reload.hpp); a bad file or a
// failure to apply it is logged and the configuration in force stays. True
// when the new configuration is in force.
bool reload_config(Supervisor& supervisor);

// agnocastd's fields of its status file; running, pid, uptime_s and
// started_at are the head's.
agnocast::DaemonStatus daemon_status(const Supervisor& supervisor,
                                     const agnocast::ServiceStatus& head);

// True when /dev/agnocast is there and answers with a compatible version.
bool module_healthy();

// Sends READY=1, then serves until SIGTERM or SIGINT (STOPPING=1 sent);
// SIGHUP reloads the configuration, then sweeps. Throws on a broken descriptor.
void serve(Supervisor& supervisor);

}  // namespace agnocastd
