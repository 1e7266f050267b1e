#include "log_forwarder.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

namespace agnocast::python {
namespace {

using namespace std::chrono_literals;

// What a consumer received, and a gate it must pass first (as the Python
// handler must take the GIL).
struct Sink {
  std::mutex gate;
  std::atomic<bool> entered{false};
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::string> lines;

  LogForwarder::Consumer consumer() {
    return [this](std::vector<LogLine>& batch) {
      entered = true;
      std::lock_guard pass(gate);
      std::lock_guard lock(mutex);
      for (const LogLine& line : batch) lines.push_back(line.text);
      changed.notify_all();
    };
  }
  bool wait_for(std::size_t count) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, 10s, [&] { return lines.size() >= count; });
  }
};

TEST(LogForwarder, PostReturnsWhileTheConsumerWaitsForItsGate) {
  Sink sink;
  LogForwarder forwarder(sink.consumer());
  {
    std::lock_guard held(sink.gate);  // this thread holds what the consumer needs
    for (int i = 0; i < 3; ++i) forwarder.post(LogLevel::warning, "line " + std::to_string(i));
  }
  ASSERT_TRUE(sink.wait_for(3));
  EXPECT_EQ(sink.lines, (std::vector<std::string>{"line 0", "line 1", "line 2"}));
}

TEST(LogForwarder, StopHandsOverEverythingWaiting) {
  Sink sink;
  LogForwarder forwarder(sink.consumer());
  for (int i = 0; i < 100; ++i) forwarder.post(LogLevel::info, std::to_string(i));
  forwarder.stop();
  ASSERT_EQ(sink.lines.size(), 100u);
  EXPECT_EQ(sink.lines.back(), "99");
  forwarder.post(LogLevel::info, "after a stop");  // starts again
  ASSERT_TRUE(sink.wait_for(101));
  EXPECT_EQ(sink.lines.back(), "after a stop");
}

TEST(LogForwarder, DropsTheOldestBeyondItsBoundAndSaysSo) {
  Sink sink;
  LogForwarder forwarder(sink.consumer());
  {
    std::lock_guard held(sink.gate);
    forwarder.post(LogLevel::warning, "first");
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (!sink.entered && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(1ms);
    }
    ASSERT_TRUE(sink.entered);  // the consumer took "first" and waits at the gate
    for (std::size_t i = 0; i < LogForwarder::max_waiting + 5; ++i) {
      forwarder.post(LogLevel::warning, std::to_string(i));
    }
  }
  forwarder.stop();
  ASSERT_EQ(sink.lines.size(), 2 + LogForwarder::max_waiting);
  EXPECT_EQ(sink.lines[0], "first");
  EXPECT_EQ(sink.lines[1], "agnocast: 5 log lines dropped (the handler fell behind)");
  EXPECT_EQ(sink.lines[2], "5");
  EXPECT_EQ(sink.lines.back(), std::to_string(LogForwarder::max_waiting + 4));
}

TEST(LogForwarder, AForkChildForwardsItsOwnLines) {
  Sink sink;
  LogForwarder forwarder(sink.consumer());
  forwarder.post(LogLevel::info, "parent");
  ASSERT_TRUE(sink.wait_for(1));
  // The consumer's thread is running; it holds none of the sink's locks at
  // the fork (the forwarder's own lock is the fork handlers' business).
  std::unique_lock gate(sink.gate);
  std::unique_lock lock(sink.mutex);
  const pid_t child = fork();
  lock.unlock();
  gate.unlock();
  ASSERT_GE(child, 0);
  if (child == 0) {
    forwarder.post(LogLevel::info, "child");
    const bool got = sink.wait_for(2) && sink.lines.back() == "child";
    _exit(got ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  forwarder.post(LogLevel::info, "parent again");
  ASSERT_TRUE(sink.wait_for(2));
  EXPECT_EQ(sink.lines.back(), "parent again");
}

}  // namespace
}  // namespace agnocast::python
