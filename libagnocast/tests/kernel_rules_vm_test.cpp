// The module follows the wake and release rules of kernel_rules.cpp, the
// table FakeKernel is held to natively (src/kernel/kernel_rules_test.cpp). Each
// process of a scenario is a forked child that registers as the library does
// (Runtime::get()) and performs the calls it is sent over a pipe on its own
// Device; a death is a real SIGKILL, waited for until the module has torn the
// process down.
#include <agnocast.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "agnocast/inspect.hpp"
#include "kernel/kernel_rules.hpp"
#include "kernel/runtime.hpp"

namespace agnocast::detail::kernel_rules {
namespace {

using namespace std::chrono_literals;

static_assert(watchdog_period == std::chrono::milliseconds(AGNOCAST_WAKE_WATCHDOG_MS));

bool write_all(int fd, const void* data, std::size_t size) {
  return ::write(fd, data, size) == static_cast<ssize_t>(size);  // < PIPE_BUF: atomic
}

// False at end of file or after timeout.
bool read_all(int fd, void* data, std::size_t size, std::chrono::milliseconds timeout) {
  pollfd entry{fd, POLLIN, 0};
  if (::poll(&entry, 1, static_cast<int>(timeout.count())) != 1) return false;
  return ::read(fd, data, size) == static_cast<ssize_t>(size);
}

bool registered(pid_t pid) {
  for (const ProcessInfo& process : list_processes()) {
    if (process.pid == pid) return true;
  }
  return false;
}

// A child's life: register, say so, then answer every call until the pipe closes.
[[noreturn]] void serve(int calls, int answers) {
  int code = 0;
  try {
    Runtime& runtime = Runtime::get();
    const auto pool_base = reinterpret_cast<std::uintptr_t>(runtime.allocate(pool_block, 64));
    Answer ready;
    if (!write_all(answers, &ready, sizeof ready)) ::_exit(2);
    Call call;
    while (read_all(calls, &call, sizeof call, 600s)) {
      const Answer answer = perform(runtime.kernel(), pool_base, call);
      if (!write_all(answers, &answer, sizeof answer)) ::_exit(2);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "kernel_rules child %d: %s\n", ::getpid(), error.what());
    code = 1;
  }
  std::fflush(nullptr);
  ::_exit(code);
}

class ForkedWorld final : public World {
 public:
  explicit ForkedWorld(int processes) {
    for (int process = 0; process < processes; ++process) spawn();
  }

  ~ForkedWorld() override {
    for (Child& child : children_) {
      if (child.pid <= 0) continue;
      ::close(child.calls);
      ::close(child.answers);
      ::waitpid(child.pid, nullptr, 0);
      torn_down(child.pid);  // the next world starts clean, or as clean as it gets
    }
  }

  Answer perform(int process, const Call& call) override {
    const Child& child = children_.at(static_cast<std::size_t>(process));
    Answer answer;
    if (!write_all(child.calls, &call, sizeof call) ||
        !read_all(child.answers, &answer, sizeof answer, 30s)) {
      throw std::runtime_error("process " + std::to_string(process) + " did not answer");
    }
    return answer;
  }

  void kill(int process) override {
    Child& child = children_.at(static_cast<std::size_t>(process));
    ::kill(child.pid, SIGKILL);
    ::waitpid(child.pid, nullptr, 0);
    ::close(child.calls);
    ::close(child.answers);
    const pid_t pid = std::exchange(child.pid, -1);
    if (!torn_down(pid)) {
      throw std::runtime_error("process " + std::to_string(pid) + " stays registered");
    }
  }

  // Timers run late under emulation: three periods.
  void pass_watchdog() override { std::this_thread::sleep_for(3 * watchdog_period); }

 private:
  struct Child {
    pid_t pid = -1;
    int calls = -1;    // written here
    int answers = -1;  // read here
  };

  void spawn() {
    int calls[2], answers[2];
    if (::pipe2(calls, O_CLOEXEC) != 0 || ::pipe2(answers, O_CLOEXEC) != 0) {
      throw std::runtime_error("pipe");
    }
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error("fork");
    if (pid == 0) {
      // An earlier sibling's pipe end left open here would keep it from seeing its end.
      for (const Child& sibling : children_) {
        ::close(sibling.calls);
        ::close(sibling.answers);
      }
      ::close(calls[1]);
      ::close(answers[0]);
      serve(calls[0], answers[1]);
    }
    ::close(calls[0]);
    ::close(answers[1]);
    children_.push_back(Child{pid, calls[1], answers[0]});
    Answer ready;
    if (!read_all(answers[0], &ready, sizeof ready, 30s)) {
      throw std::runtime_error("a process did not register");
    }
  }

  // The module tears a process down when its last descriptor of the device
  // closes; false when it is still registered 10 s after its death.
  static bool torn_down(pid_t pid) noexcept {
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    try {
      while (registered(pid)) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(1ms);
      }
      return true;
    } catch (const std::exception&) {
      return false;
    }
  }

  std::vector<Child> children_;
};

class KernelRules : public ::testing::TestWithParam<const Scenario*> {};

TEST_P(KernelRules, TheModuleFollowsThem) {
  const Scenario& scenario = *GetParam();
  const auto make_world = [](int processes) { return std::make_unique<ForkedWorld>(processes); };
  int runs = 0;
  EXPECT_EQ(check(scenario, make_world, &runs), "") << scenario.rule;
  if (runs > 1) std::printf("%d runs: the earlier ones were too slow to judge\n", runs);
}

INSTANTIATE_TEST_SUITE_P(Table, KernelRules, ::testing::ValuesIn(every_scenario()),
                         [](const auto& info) { return info.param->name; });

}  // namespace
}  // namespace agnocast::detail::kernel_rules
