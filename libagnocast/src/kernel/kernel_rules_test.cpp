// FakeKernel follows the module's wake and release rules: the table of
// kernel_rules.cpp, which tests/kernel_rules_vm_test.cpp runs against the
// module in the VM.
#include "kernel/kernel_rules.hpp"

#include <gtest/gtest.h>
#include <sys/types.h>

#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "kernel/fake_kernel.hpp"

namespace agnocast::detail::kernel_rules {
namespace {

static_assert(FakeKernel::watchdog_period == watchdog_period);

// One FakeKernel; process k is pid 1000 + k, its pool block at (k + 1) GiB.
class FakeWorld final : public World {
 public:
  explicit FakeWorld(int processes) {
    // Each process has its wake eventfd from the start, as the library's registration gives it.
    for (int process = 0; process < processes; ++process) {
      kernel_.set_caller_pid(pid(process));
      kernel_.wake_fd();
    }
  }

  Answer perform(int process, const Call& call) override {
    kernel_.set_caller_pid(pid(process));
    return kernel_rules::perform(kernel_, (std::uint64_t{1} << 30) * (process + 1), call);
  }
  void kill(int process) override { kernel_.end_process(pid(process)); }
  void pass_watchdog() override {
    std::this_thread::sleep_for(watchdog_period + std::chrono::milliseconds(5));
    kernel_.run_watchdog();
  }

 private:
  static pid_t pid(int process) { return 1000 + process; }

  FakeKernel kernel_;
};

class KernelRules : public ::testing::TestWithParam<const Scenario*> {};

TEST_P(KernelRules, FakeKernelFollowsThem) {
  const Scenario& scenario = *GetParam();
  const auto make_world = [](int processes) { return std::make_unique<FakeWorld>(processes); };
  int runs = 0;
  EXPECT_EQ(check(scenario, make_world, &runs), "") << scenario.rule;
  if (runs > 1) std::printf("%d runs: the earlier ones were too slow to judge\n", runs);
}

INSTANTIATE_TEST_SUITE_P(Table, KernelRules, ::testing::ValuesIn(every_scenario()),
                         [](const auto& info) { return info.param->name; });

}  // namespace
}  // namespace agnocast::detail::kernel_rules
