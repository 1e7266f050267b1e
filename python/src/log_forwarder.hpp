// Hands the library's log lines to a consumer on a thread of its own.
//
// The library may log from any thread while it holds one of its locks (a
// failed release logs under the subscription's release lock). A Python
// handler needs the GIL, and a thread holding the GIL may be waiting for that
// very lock (dropping a message releases it): calling the handler in place
// could deadlock. post() only queues, never waits for the consumer; the
// forwarder's thread, which holds no lock of the library, calls it.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "agnocast/log.hpp"

namespace agnocast::python {

struct LogLine {
  LogLevel level;
  std::string text;
};

class LogForwarder {
 public:
  using Consumer = std::function<void(std::vector<LogLine>& lines)>;
  // At most this many lines wait; older ones are dropped, and counted in a line.
  static constexpr std::size_t max_waiting = 1024;

  explicit LogForwarder(Consumer consumer);
  ~LogForwarder();  // stop()
  LogForwarder(const LogForwarder&) = delete;
  LogForwarder& operator=(const LogForwarder&) = delete;

  // From any thread; returns at once. The thread starts with the first line
  // (again in a fork child, which has none).
  void post(LogLevel level, std::string_view text);
  // Hands over what waits, then ends the thread; post() starts it again.
  void stop();

 private:
  void run();
  static void before_fork();
  static void after_fork_in_parent();
  static void after_fork_in_child();

  Consumer consumer_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<LogLine> waiting_;
  std::size_t dropped_ = 0;
  bool stopping_ = false;
  std::unique_ptr<std::thread> thread_;  // none until the first line
};

}  // namespace agnocast::python
