// The lifecycle every agnocast daemon shares, written once: one instance at a
// time (the lock beside its status file), the stop and reload signals as a
// descriptor, READY=1 with a STATUS= line, the watchdog, the status file
// (agnocast/status.hpp's head, then the daemon's own fields) at ready, every
// second and at stop, STOPPING=1, and the last status when it has stopped.
//
//   agnocast_service::ServiceLoop service({.program = "x", .status_path = "/run/agnocast/x.json"});
//   // ... start up; threads may start now (the signals are blocked) ...
//   service.add_fd(work.fd(), "x's work", [&] { work.handle(); });
//   service.ready("serving 3 topics", {.status_body = [&](const auto&) { return x_fields(); }});
//   service.run();       // until SIGTERM, SIGINT (or SIGHUP without a reload hook)
//   // ... finish the work in hand ...
//   service.stopped();   // the last status: "state":"stopped"
//
// A daemon with a loop of its own polls fd() in it and calls dispatch() when
// it is readable (agnocast-bridge: its executor's add_fd; agnocast-foxglove:
// its client loop's poll) until dispatch() returns false.
#pragma once

#include <signal.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "agnocast/status.hpp"
#include "agnocast_service/instance_lock.hpp"
#include "agnocast_service/signals.hpp"
#include "agnocast_service/timer.hpp"
#include "agnocast_service/unique_fd.hpp"
#include "agnocast_service/watchdog.hpp"

namespace agnocast_service {

// SIGTERM, SIGINT and SIGHUP: what a ServiceLoop blocks and reads.
sigset_t service_signals();

struct ServiceOptions {
  // The status head's "program" and the name in "already running" errors.
  std::string program;
  // The status file; the instance lock is agnocast::lock_path_beside(status_path).
  std::string status_path;
  // How often the status file is rewritten while the daemon runs.
  std::chrono::milliseconds status_interval = std::chrono::seconds(1);
  // For a program an unprivileged user runs too: where the status file's
  // folder is not writable, serve without the status file and the lock (with
  // a warning) instead of failing.
  bool status_optional = false;
};

struct ServiceHooks {
  // The daemon's own fields, written after the head (a field the head has
  // keeps the head's value). Called on the loop's thread; none: the head alone.
  std::function<nlohmann::json(const agnocast::ServiceStatus& head)> status_body = {};
  // SIGHUP: re-read the configuration. None: SIGHUP stops the daemon as SIGTERM does.
  std::function<void()> reload = {};
  // Asked before each watchdog ping; false withholds the ping (systemd then
  // restarts the daemon), so the hook logs why. None: always healthy.
  std::function<bool()> healthy = {};
};

class ServiceLoop {
 public:
  // Takes the lock (throws AlreadyRunning while another instance holds it,
  // std::system_error when it cannot), then blocks service_signals() in the
  // calling thread: construct it before any thread starts, so that every
  // thread inherits the mask (or block them first, as agnocast-bridge does
  // to start DDS before it takes the lock). Writes nothing yet.
  explicit ServiceLoop(ServiceOptions options);
  // Writes the last status ("stopped", with the last fields the body gave)
  // if ready() was called and stopped() was not: a failure's way out.
  ~ServiceLoop();
  ServiceLoop(const ServiceLoop&) = delete;
  ServiceLoop& operator=(const ServiceLoop&) = delete;

  // The daemon's own descriptors, served by dispatch() and run(): on_readable
  // runs when fd is readable; an error on fd throws std::runtime_error
  // naming `what`. The descriptor stays the caller's; remove it before closing it.
  void add_fd(int fd, std::string what, std::function<void()> on_readable);
  void remove_fd(int fd);

  // Started: writes the status ("running"), sends READY=1 and STATUS=status,
  // starts the status timer. The hooks are called from here on.
  void ready(std::string_view status, ServiceHooks hooks);

  // Readable when dispatch() has something to do (an epoll descriptor).
  int fd() const { return epoll_.get(); }
  // Handles what is ready, without waiting: signals, the watchdog, the status
  // timer and the daemon's descriptors. On a stop signal it sends STOPPING=1
  // and writes the status ("stopping"). False once stopping.
  bool dispatch();
  // Waits and dispatches until a stop signal.
  void run();
  // A stop signal came.
  bool stopping() const { return state_ != agnocast::ServiceState::running; }

  // Writes the status file now (after work that changed the daemon's fields);
  // logs, never throws, when it cannot.
  void write_status();
  // The last status ("stopped"), after the daemon finished its work. Sends
  // STOPPING=1 first if no stop signal came.
  void stopped();

 private:
  // Waits up to timeout_ms (-1: forever) and handles what is ready; false once stopping.
  bool handle_events(int timeout_ms);
  void watch(int fd, std::string what, std::function<void()> on_readable);
  void read_signals();
  void begin_stop();
  agnocast::ServiceStatus head() const;
  void write(const nlohmann::json& body);

  struct Watched {
    std::string what;
    std::function<void()> on_readable;
  };

  ServiceOptions options_;
  std::optional<InstanceLock> lock_;  // none: serving without a status file
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::chrono::system_clock::time_point started_at_ = std::chrono::system_clock::now();
  UniqueFd epoll_;
  SignalFd signals_;
  Watchdog watchdog_;
  PeriodicTimer status_timer_;
  std::map<int, Watched> watched_;
  ServiceHooks hooks_;
  bool ready_ = false;
  bool stop_requested_ = false;
  agnocast::ServiceState state_ = agnocast::ServiceState::running;
  nlohmann::json last_body_ = nlohmann::json::object();
};

}  // namespace agnocast_service
