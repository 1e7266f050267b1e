#include "event_loop.hpp"

#include <poll.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <system_error>

#include "agnocast/inspect.hpp"
#include "agnocast/status.hpp"
#include "agnocast_service/atomic_file.hpp"
#include "agnocast_service/errno_error.hpp"
#include "agnocast_service/signals.hpp"
#include "agnocast_service/timer.hpp"
#include "agnocast_service/watchdog.hpp"
#include "daemon_signals.hpp"
#include "module_loader.hpp"
#include "reload.hpp"
#include "sweeper.hpp"

namespace agnocastd {

namespace {

void sweep_now(Supervisor& supervisor) {
  sweep(supervisor.host, supervisor.counters);
  write_status(supervisor, /*running=*/true);
}

}  // namespace

void clean_exited_processes(Supervisor& supervisor) {
  bool cleaned = false;
  for (auto records = supervisor.exit_records.read_available(); !records.empty();
       records = supervisor.exit_records.read_available()) {
    cleaned |=
        handle_exit_records(records, supervisor.collector, supervisor.host, supervisor.counters);
  }
  if (cleaned) write_status(supervisor, /*running=*/true);
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

void write_status(const Supervisor& supervisor, bool running) {
  using std::chrono::duration_cast;
  agnocast::DaemonStatus status;
  status.running = running;
  status.pid = ::getpid();
  status.module_version = supervisor.module_version;
  status.uptime_s = static_cast<std::uint64_t>(
      duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - supervisor.started)
          .count());
  status.started_at =
      duration_cast<std::chrono::seconds>(supervisor.started_at.time_since_epoch()).count();
  status.counters = supervisor.counters;
  try {
    agnocast_service::write_file_atomically(supervisor.status_path, agnocast::to_json(status));
  } catch (const std::exception& error) {
    spdlog::error("cannot write the status file: {}", error.what());
  }
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
  agnocast_service::SignalFd signals(daemon_signals());
  agnocast_service::PeriodicTimer sweep_timer(supervisor.config.sweep_interval);
  agnocast_service::Watchdog watchdog;
  if (const auto period = watchdog.interval()) {
    spdlog::info("pinging the systemd watchdog every {} ms", period->count() / 1000);
  }

  enum { exit_records, stop_signals, sweep_tick, watchdog_tick };
  std::array<pollfd, 4> fds{{
      {supervisor.exit_records.fd(), POLLIN, 0},
      {signals.fd(), POLLIN, 0},
      {sweep_timer.fd(), POLLIN, 0},
      {watchdog.fd(), POLLIN, 0},
  }};
  for (;;) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      agnocast_service::throw_errno("poll");
    }
    if (fds[exit_records].revents & (POLLERR | POLLNVAL)) {
      throw std::runtime_error("the exit-record descriptor of /dev/agnocast failed");
    }
    if (fds[exit_records].revents & POLLIN) clean_exited_processes(supervisor);
    if (fds[stop_signals].revents & POLLIN) {
      while (const auto signal = signals.read()) {
        if (*signal != SIGHUP) {
          spdlog::info("received {}, stopping", strsignal(*signal));
          return;
        }
        spdlog::info("received SIGHUP, reloading the configuration");
        const auto sweep_interval = supervisor.config.sweep_interval;
        if (reload_config(supervisor) && supervisor.config.sweep_interval != sweep_interval) {
          sweep_timer.arm(supervisor.config.sweep_interval);
          spdlog::info("sweeping every {} ms", supervisor.config.sweep_interval.count());
        }
        sweep_now(supervisor);
      }
    }
    if (fds[sweep_tick].revents & POLLIN) {
      sweep_timer.consume();
      sweep_now(supervisor);
    }
    if (fds[watchdog_tick].revents & POLLIN) {
      // No ping when unhealthy: systemd then restarts the daemon.
      const bool healthy = module_healthy();
      watchdog.tick(healthy);
      if (healthy) {
        spdlog::debug("watchdog ping");
      } else {
        spdlog::error(
            "health check failed: /dev/agnocast does not answer; not pinging the watchdog");
      }
    }
  }
}

}  // namespace agnocastd
