#include "log_forwarder.hpp"

#include <pthread.h>

#include <algorithm>
#include <utility>

namespace agnocast::python {
namespace {

// Every forwarder, for the fork handlers (the binding makes one).
std::mutex& registry_mutex() {
  static auto* mutex = new std::mutex;
  return *mutex;
}
std::vector<LogForwarder*>& registry() {
  static auto* forwarders = new std::vector<LogForwarder*>;
  return *forwarders;
}

}  // namespace

LogForwarder::LogForwarder(Consumer consumer) : consumer_(std::move(consumer)) {
  static const bool handlers = [] {
    return pthread_atfork(&before_fork, &after_fork_in_parent, &after_fork_in_child) == 0;
  }();
  (void)handlers;
  std::lock_guard lock(registry_mutex());
  registry().push_back(this);
}

LogForwarder::~LogForwarder() {
  stop();
  std::lock_guard lock(registry_mutex());
  std::erase(registry(), this);
}

void LogForwarder::post(LogLevel level, std::string_view text) {
  std::lock_guard lock(mutex_);
  if (waiting_.size() >= max_waiting) {
    waiting_.pop_front();
    ++dropped_;
  }
  waiting_.push_back({level, std::string(text)});
  if (!thread_) {
    stopping_ = false;
    thread_ = std::make_unique<std::thread>([this] { run(); });
  }
  wake_.notify_one();
}

void LogForwarder::stop() {
  std::thread ending;
  {
    std::lock_guard lock(mutex_);
    if (!thread_) return;
    stopping_ = true;
    ending = std::move(*thread_);
    thread_.reset();
  }
  wake_.notify_one();
  ending.join();
}

void LogForwarder::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
    if (waiting_.empty()) return;  // stopping, and everything handed over
    std::vector<LogLine> lines;
    if (dropped_) {
      lines.push_back({LogLevel::warning, "agnocast: " + std::to_string(dropped_) +
                                              " log lines dropped (the handler fell behind)"});
      dropped_ = 0;
    }
    lines.insert(lines.end(), std::make_move_iterator(waiting_.begin()),
                 std::make_move_iterator(waiting_.end()));
    waiting_.clear();
    lock.unlock();
    consumer_(lines);
    lock.lock();
  }
}

// A fork must not copy a forwarder's mutex while another thread holds it.
void LogForwarder::before_fork() {
  registry_mutex().lock();
  for (LogForwarder* forwarder : registry()) forwarder->mutex_.lock();
}

void LogForwarder::after_fork_in_parent() {
  for (LogForwarder* forwarder : registry()) forwarder->mutex_.unlock();
  registry_mutex().unlock();
}

void LogForwarder::after_fork_in_child() {
  // The thread is the parent's alone: forget it (its handle means nothing
  // here); post() starts one of this process.
  for (LogForwarder* forwarder : registry()) {
    [[maybe_unused]] std::thread* parents = forwarder->thread_.release();
    forwarder->mutex_.unlock();
  }
  registry_mutex().unlock();
}

}  // namespace agnocast::python
