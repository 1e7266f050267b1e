#include "agnocast_service/service_loop.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "agnocast/status.hpp"
#include "agnocast/version.hpp"
#include "fake_notify_socket.hpp"
#include "readable.hpp"

namespace agnocast_service {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

// A status file in a folder of its own (ctest runs each test in a process
// of its own, side by side: the pid keeps their locks apart), removed with it.
class ServiceLoopTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::remove_all(directory_);
    ::unsetenv("WATCHDOG_USEC");
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  ServiceOptions options() const { return {.program = "x", .status_path = status_path_}; }
  std::string read_status() const {
    std::ifstream file(status_path_);
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  }
  json status() const { return json::parse(read_status()); }

  const std::filesystem::path directory_ = std::filesystem::path(::testing::TempDir()) /
                                           ("agnocast-service-loop-" + std::to_string(::getpid()));
  const std::string status_path_ = (directory_ / "x.json").string();
  const std::string lock_path_ = (directory_ / "x.lock").string();
};

// Dispatches until it returns false or `wait` has passed; its last result.
bool dispatch_until_stopping(ServiceLoop& service, std::chrono::milliseconds wait) {
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < deadline) {
    if (readable(service.fd(), 10ms) && !service.dispatch()) return false;
  }
  return true;
}

TEST_F(ServiceLoopTest, HoldsTheLockBesideTheStatusFileAndWritesNothingBeforeReady) {
  ServiceLoop service(options());
  std::string pid;
  std::ifstream(lock_path_) >> pid;
  EXPECT_EQ(pid, std::to_string(::getpid()));
  EXPECT_FALSE(std::filesystem::exists(status_path_));
  try {
    ServiceLoop second(options());
    ADD_FAILURE() << "a second instance took the lock";
  } catch (const AlreadyRunning& error) {
    EXPECT_EQ(std::string(error.what()),
              "x is already running (pid " + std::to_string(::getpid()) + ")");
  }
}

TEST_F(ServiceLoopTest, ReadyWritesTheHeadThenTheBodyAndNotifiesWithTheStatusLine) {
  FakeNotifySocket systemd("agnocast-service-loop-ready");
  ServiceLoop service(options());
  service.ready("serving 3 things", {.status_body = [](const agnocast::ServiceStatus& head) {
                  // The head's pid wins over a body's.
                  return json{{"things", 3}, {"pid", head.pid + 1}};
                }});
  EXPECT_EQ(systemd.received(), "READY=1\nSTATUS=serving 3 things");

  const std::string text = read_status();
  EXPECT_EQ(text.back(), '\n');
  const auto ordered = nlohmann::ordered_json::parse(text);
  std::vector<std::string> keys;
  for (const auto& [key, value] : ordered.items()) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"program", "pid", "version", "state", "running",
                                            "started_at", "uptime_s", "written_at", "things"}));
  const agnocast::ServiceStatus head = agnocast::service_status_from_json(text);
  EXPECT_EQ(head.program, "x");
  EXPECT_EQ(head.pid, ::getpid());
  EXPECT_EQ(head.version, agnocast::library_version_string);
  EXPECT_EQ(head.state, agnocast::ServiceState::running);
  EXPECT_LE(head.started_at, head.written_at);
  EXPECT_EQ(ordered["things"], 3);
  struct stat info {};
  ASSERT_EQ(::stat(status_path_.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0644u);
}

TEST_F(ServiceLoopTest, RewritesTheStatusEveryInterval) {
  ServiceOptions fast = options();
  fast.status_interval = 10ms;
  ServiceLoop service(fast);
  int writes = 0;
  service.ready("", {.status_body = [&writes](const auto&) { return json{{"writes", ++writes}}; }});
  // Three writes take 20 ms; a loaded machine gets up to 5 s.
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (writes < 3 && std::chrono::steady_clock::now() < deadline) {
    EXPECT_TRUE(dispatch_until_stopping(service, 10ms));
  }
  EXPECT_GE(status()["writes"].get<int>(), 3);
}

TEST_F(ServiceLoopTest, SigtermStopsWithStoppingThenTheLastStatusStopped) {
  FakeNotifySocket systemd("agnocast-service-loop-stop");
  ServiceLoop service(options());
  int work = 1;
  service.ready("", {.status_body = [&work](const auto&) { return json{{"work", work}}; }});
  systemd.received();
  ::raise(SIGTERM);
  EXPECT_FALSE(dispatch_until_stopping(service, 1000ms));
  EXPECT_TRUE(service.stopping());
  EXPECT_FALSE(service.dispatch());
  EXPECT_EQ(systemd.received(), "STOPPING=1");
  EXPECT_EQ(status()["state"], "stopping");
  EXPECT_EQ(status()["running"], true);

  work = 2;  // finished after the stop signal
  service.stopped();
  EXPECT_EQ(status()["state"], "stopped");
  EXPECT_EQ(status()["running"], false);
  EXPECT_EQ(status()["work"], 2);
  EXPECT_EQ(systemd.received(), "");  // STOPPING=1 once
}

TEST_F(ServiceLoopTest, SighupReloadsWhenTheDaemonCanElseStops) {
  {
    ServiceLoop service(options());
    int reloads = 0;
    service.ready("", {.reload = [&reloads] { ++reloads; }});
    ::raise(SIGHUP);
    EXPECT_TRUE(dispatch_until_stopping(service, 100ms));
    EXPECT_EQ(reloads, 1);
    service.stopped();
  }
  ServiceLoop service(options());
  service.ready("", {});
  ::raise(SIGHUP);
  EXPECT_FALSE(dispatch_until_stopping(service, 1000ms));
}

TEST_F(ServiceLoopTest, RunServesTheDaemonsDescriptorsUntilAStopSignal) {
  ServiceLoop service(options());
  const UniqueFd work(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  int handled = 0;
  service.add_fd(work.get(), "the work", [&] {
    std::uint64_t count = 0;
    ASSERT_EQ(::read(work.get(), &count, sizeof count), static_cast<ssize_t>(sizeof count));
    if (++handled == 2) ::raise(SIGINT);
  });
  service.ready("", {});
  const std::uint64_t one = 1;
  ASSERT_EQ(::write(work.get(), &one, sizeof one), static_cast<ssize_t>(sizeof one));
  EXPECT_TRUE(dispatch_until_stopping(service, 50ms));
  EXPECT_EQ(handled, 1);
  ASSERT_EQ(::write(work.get(), &one, sizeof one), static_cast<ssize_t>(sizeof one));
  service.run();  // returns on the SIGINT of the second call
  EXPECT_EQ(handled, 2);
  service.remove_fd(work.get());
}

TEST_F(ServiceLoopTest, TheWatchdogPingsOnlyWhileHealthy) {
  FakeNotifySocket systemd("agnocast-service-loop-watchdog");
  ::unsetenv("WATCHDOG_PID");
  ::setenv("WATCHDOG_USEC", "20000", 1);  // a ping every 10 ms
  ServiceLoop service(options());
  ::unsetenv("WATCHDOG_USEC");
  bool healthy = false;
  service.ready("", {.healthy = [&healthy] { return healthy; }});
  EXPECT_EQ(systemd.received(), "READY=1\nSTATUS=");
  EXPECT_TRUE(dispatch_until_stopping(service, 50ms));
  EXPECT_EQ(systemd.received(), "");
  healthy = true;
  EXPECT_TRUE(dispatch_until_stopping(service, 50ms));
  EXPECT_EQ(systemd.received(), "WATCHDOG=1");
}

TEST_F(ServiceLoopTest, AFailureWritesTheLastStatusWithTheLastFields) {
  {
    ServiceLoop service(options());
    int work = 7;
    service.ready("", {.status_body = [&work](const auto&) { return json{{"work", work}}; }});
    work = 8;  // gone before the destructor: not asked again
  }
  EXPECT_EQ(status()["state"], "stopped");
  EXPECT_EQ(status()["running"], false);
  EXPECT_EQ(status()["work"], 7);
}

}  // namespace
}  // namespace agnocast_service
