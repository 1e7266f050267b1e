#include "agnocast_service/service_loop.hpp"

#include <spdlog/spdlog.h>
#include <sys/epoll.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "agnocast/version.hpp"
#include "agnocast_service/errno_error.hpp"
#include "agnocast_service/notify.hpp"
#include "agnocast_service/status_file.hpp"

namespace agnocast_service {
namespace {

bool not_permitted(const std::system_error& error) {
  return error.code() == std::errc::permission_denied ||
         error.code() == std::errc::operation_not_permitted ||
         error.code() == std::errc::read_only_file_system;
}

std::int64_t unix_seconds(std::chrono::system_clock::time_point time) {
  return std::chrono::duration_cast<std::chrono::seconds>(time.time_since_epoch()).count();
}

}  // namespace

sigset_t service_signals() { return signal_set({SIGTERM, SIGINT, SIGHUP}); }

ServiceLoop::ServiceLoop(ServiceOptions options)
    : options_(std::move(options)),
      epoll_(::epoll_create1(EPOLL_CLOEXEC)),
      signals_(service_signals()),
      status_timer_(std::chrono::microseconds{0}) {
  if (!epoll_) throw_errno("epoll_create1");
  // One instance at a time, before anything else.
  try {
    lock_.emplace(agnocast::lock_path_beside(options_.status_path), options_.program);
  } catch (const std::system_error& error) {
    if (!options_.status_optional || !not_permitted(error)) throw;
    spdlog::warn(
        "serving without the status file {} ({}): agnocast-cli daemon status will not "
        "show {}",
        options_.status_path, error.what(), options_.program);
    options_.status_path.clear();
  }
  // From here the signals queue for signals_, in every thread started later.
  block_signals(service_signals());
  watch(signals_.fd(), "the signal descriptor", [this] { read_signals(); });
  watch(watchdog_.fd(), "the watchdog timer",
        [this] { watchdog_.tick(!hooks_.healthy || hooks_.healthy()); });
  watch(status_timer_.fd(), "the status timer", [this] {
    status_timer_.consume();
    write_status();
  });
}

ServiceLoop::~ServiceLoop() {
  if (!ready_ || state_ == agnocast::ServiceState::stopped) return;
  // The body's owners may be gone: the last fields it gave.
  state_ = agnocast::ServiceState::stopped;
  try {
    write(last_body_);
  } catch (...) {
  }
}

void ServiceLoop::watch(int fd, std::string what, std::function<void()> on_readable) {
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = fd;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &event) != 0) {
    throw_errno("cannot watch " + what);
  }
  watched_[fd] = Watched{std::move(what), std::move(on_readable)};
}

void ServiceLoop::add_fd(int fd, std::string what, std::function<void()> on_readable) {
  watch(fd, std::move(what), std::move(on_readable));
}

void ServiceLoop::remove_fd(int fd) {
  if (watched_.erase(fd) > 0) ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, fd, nullptr);
}

void ServiceLoop::ready(std::string_view status, ServiceHooks hooks) {
  hooks_ = std::move(hooks);
  ready_ = true;
  write_status();
  notify("READY=1\nSTATUS=" + std::string(status));
  status_timer_.arm(options_.status_interval);
  if (const auto period = watchdog_.interval()) {
    spdlog::info("pinging the systemd watchdog every {} ms", period->count() / 1000);
  }
}

bool ServiceLoop::dispatch() { return handle_events(0); }

void ServiceLoop::run() {
  while (handle_events(-1)) {
  }
}

bool ServiceLoop::handle_events(int timeout_ms) {
  if (stopping()) return false;
  std::array<epoll_event, 16> events{};
  const int count = ::epoll_wait(epoll_.get(), events.data(), events.size(), timeout_ms);
  if (count < 0) {
    if (errno == EINTR) return true;
    throw_errno("epoll_wait");
  }
  for (int i = 0; i < count; ++i) {
    // A handler earlier in this batch may have removed it.
    const auto found = watched_.find(events[i].data.fd);
    if (found == watched_.end()) continue;
    if ((events[i].events & EPOLLERR) != 0 && (events[i].events & EPOLLIN) == 0) {
      throw std::runtime_error(found->second.what + " failed");
    }
    // A copy: the handler may remove its own descriptor.
    const std::function<void()> on_readable = found->second.on_readable;
    on_readable();
  }
  if (stop_requested_ && !stopping()) begin_stop();
  return !stopping();
}

void ServiceLoop::read_signals() {
  while (const auto signal = signals_.read()) {
    if (*signal == SIGHUP && hooks_.reload) {
      spdlog::info("received SIGHUP, reloading the configuration");
      hooks_.reload();
      continue;
    }
    spdlog::info("received {}, stopping", strsignal(*signal));
    stop_requested_ = true;
  }
}

void ServiceLoop::begin_stop() {
  notify("STOPPING=1");
  state_ = agnocast::ServiceState::stopping;
  write_status();
}

void ServiceLoop::stopped() {
  if (!stopping()) begin_stop();
  state_ = agnocast::ServiceState::stopped;
  write_status();
}

agnocast::ServiceStatus ServiceLoop::head() const {
  const auto uptime =
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - started_);
  return {options_.program,
          ::getpid(),
          std::string(agnocast::library_version_string),
          state_,
          unix_seconds(started_at_),
          static_cast<std::uint64_t>(uptime.count()),
          unix_seconds(std::chrono::system_clock::now())};
}

void ServiceLoop::write_status() {
  if (!ready_) return;
  try {
    if (hooks_.status_body) last_body_ = hooks_.status_body(head());
    write(last_body_);
  } catch (const std::exception& error) {
    spdlog::error("cannot write the status file: {}", error.what());
  }
}

void ServiceLoop::write(const nlohmann::json& body) {
  if (!options_.status_path.empty()) write_status_file(options_.status_path, head(), body);
}

}  // namespace agnocast_service
