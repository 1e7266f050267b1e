#include "event_loop.hpp"

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>
#include <utility>

#include "agnocast/inspect.hpp"
#include "agnocast/version.hpp"
#include "agnocast_service/timer.hpp"
#include "module_loader.hpp"
#include "reload.hpp"
#include "sweeper.hpp"

namespace agnocastd {

namespace {

void sweep_now(Supervisor& supervisor) {
  sweep(supervisor.host, supervisor.counters);
  supervisor.service.write_status();
}

}  // namespace

void clean_exited_processes(Supervisor& supervisor) {
  bool cleaned = false;
  for (auto records = supervisor.exit_records.read_available(); !records.empty();
       records = supervisor.exit_records.read_available()) {
    cleaned |=
        handle_exit_records(records, supervisor.collector, supervisor.host, supervisor.counters);
  }
  if (cleaned) supervisor.service.write_status();
}

bool reload_config(Supervisor& supervisor) {
  Config next;
  try {
    next = supervisor.reread_config();
    apply_runtime_config(supervisor.config, next);
  } catch (const std::exception& error) {
    spdlog::error("configuration not reloaded, the one in force stays: {}", error.what());
    return false;
  }
  for (const std::string& difference : restart_only_differences(supervisor.config, next)) {
    spdlog::warn("{}", difference);
  }
  supervisor.config = std::move(next);
  spdlog::info("configuration reloaded");
  return true;
}

agnocast::DaemonStatus daemon_status(const Supervisor& supervisor,
                                     const agnocast::ServiceStatus& head) {
  agnocast::DaemonStatus status;
  status.running = head.running();
  status.pid = head.pid;
  status.module_version = supervisor.module_version;
  status.uptime_s = head.uptime_s;
  status.started_at = head.started_at;
  status.counters = supervisor.counters;
  return status;
}

bool module_healthy() {
  try {
    const auto version = agnocast::module_version();
    return version && version_problem(*version).empty();
  } catch (const std::exception& error) {
    spdlog::error("health check: {}", error.what());
    return false;
  }
}

void serve(Supervisor& supervisor) {
  agnocast_service::ServiceLoop& service = supervisor.service;
  agnocast_service::PeriodicTimer sweep_timer(supervisor.config.sweep_interval);
  service.add_fd(supervisor.exit_records.fd(), "the exit-record descriptor of /dev/agnocast",
                 [&supervisor] { clean_exited_processes(supervisor); });
  service.add_fd(sweep_timer.fd(), "the sweep timer", [&supervisor, &sweep_timer] {
    sweep_timer.consume();
    sweep_now(supervisor);
  });
  agnocast_service::ServiceHooks hooks;
  hooks.status_body = [&supervisor](const agnocast::ServiceStatus& head) {
    return nlohmann::json::parse(agnocast::to_json(daemon_status(supervisor, head)));
  };
  hooks.reload = [&supervisor, &sweep_timer] {
    const auto sweep_interval = supervisor.config.sweep_interval;
    if (reload_config(supervisor) && supervisor.config.sweep_interval != sweep_interval) {
      sweep_timer.arm(supervisor.config.sweep_interval);
      spdlog::info("sweeping every {} ms", supervisor.config.sweep_interval.count());
    }
    sweep_now(supervisor);
  };
  // No ping when unhealthy: systemd then restarts the daemon.
  hooks.healthy = [] {
    const bool healthy = module_healthy();
    if (healthy) {
      spdlog::debug("watchdog ping");
    } else {
      spdlog::error("health check failed: /dev/agnocast does not answer; not pinging the watchdog");
    }
    return healthy;
  };
  service.ready(
      "cleaning up after agnocast processes (agnocast.ko " + supervisor.module_version + ")",
      std::move(hooks));
  spdlog::info("agnocastd {} ready", agnocast::library_version_string);
  service.run();
  service.remove_fd(sweep_timer.fd());
  service.remove_fd(supervisor.exit_records.fd());
}

}  // namespace agnocastd
