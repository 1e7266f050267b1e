#include "event_loop.hpp"

#include <poll.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <system_error>

#include "agnocast/inspect.hpp"
#include "agnocast/status.hpp"
#include "daemon_signals.hpp"
#include "errno_error.hpp"
#include "module_loader.hpp"
#include "notify.hpp"
#include "reload.hpp"
#include "status_file.hpp"
#include "sweeper.hpp"

namespace agnocastd {

namespace {

// A descriptor closed when the scope ends.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// (Re)starts a timer to fire every period from now.
void arm_timer(int fd, std::chrono::microseconds period) {
  itimerspec spec{};
  spec.it_interval.tv_sec = period.count() / 1'000'000;
  spec.it_interval.tv_nsec = (period.count() % 1'000'000) * 1000;
  spec.it_value = spec.it_interval;
  if (::timerfd_settime(fd, 0, &spec, nullptr) != 0) throw_errno("timerfd_settime");
}

// A periodic timer, or a descriptor that never fires when period is zero.
int periodic_timer(std::chrono::microseconds period) {
  const int fd = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (fd < 0) throw_errno("timerfd_create");
  if (period.count() > 0) arm_timer(fd, period);
  return fd;
}

void drain_timer(int fd) {
  std::uint64_t expirations = 0;
  [[maybe_unused]] const auto ignored = ::read(fd, &expirations, sizeof(expirations));
}

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
    write_status_file(supervisor.status_path, agnocast::to_json(status));
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
  const sigset_t signals = daemon_signals();
  const Fd signal_fd(::signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC));
  if (signal_fd.get() < 0) throw_errno("signalfd");
  const Fd sweep_timer(periodic_timer(supervisor.config.sweep_interval));
  const auto watchdog_period = watchdog_ping_interval();
  const Fd watchdog_timer(periodic_timer(watchdog_period.value_or(std::chrono::microseconds{0})));
  if (watchdog_period) {
    spdlog::info("pinging the systemd watchdog every {} ms", watchdog_period->count() / 1000);
  }

  enum { exit_records, stop_signals, sweep_tick, watchdog_tick };
  std::array<pollfd, 4> fds{{
      {supervisor.exit_records.fd(), POLLIN, 0},
      {signal_fd.get(), POLLIN, 0},
      {sweep_timer.get(), POLLIN, 0},
      {watchdog_timer.get(), POLLIN, 0},
  }};
  for (;;) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw_errno("poll");
    }
    if (fds[exit_records].revents & (POLLERR | POLLNVAL)) {
      throw std::runtime_error("the exit-record descriptor of /dev/agnocast failed");
    }
    if (fds[exit_records].revents & POLLIN) clean_exited_processes(supervisor);
    if (fds[stop_signals].revents & POLLIN) {
      signalfd_siginfo info{};
      while (::read(signal_fd.get(), &info, sizeof(info)) == sizeof(info)) {
        if (info.ssi_signo != SIGHUP) {
          spdlog::info("received {}, stopping", strsignal(static_cast<int>(info.ssi_signo)));
          return;
        }
        spdlog::info("received SIGHUP, reloading the configuration");
        const auto sweep_interval = supervisor.config.sweep_interval;
        if (reload_config(supervisor) && supervisor.config.sweep_interval != sweep_interval) {
          arm_timer(sweep_timer.get(), supervisor.config.sweep_interval);
          spdlog::info("sweeping every {} ms", supervisor.config.sweep_interval.count());
        }
        sweep_now(supervisor);
      }
    }
    if (fds[sweep_tick].revents & POLLIN) {
      drain_timer(sweep_timer.get());
      sweep_now(supervisor);
    }
    if (fds[watchdog_tick].revents & POLLIN) {
      drain_timer(watchdog_timer.get());
      // No ping when unhealthy: systemd then restarts the daemon.
      if (module_healthy()) {
        notify("WATCHDOG=1");
        spdlog::debug("watchdog ping");
      } else {
        spdlog::error(
            "health check failed: /dev/agnocast does not answer; not pinging the watchdog");
      }
    }
  }
}

}  // namespace agnocastd
