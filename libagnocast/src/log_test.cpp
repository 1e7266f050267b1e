#include "agnocast/log.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <string>
#include <vector>

#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"

namespace agnocast::detail {
namespace {

using LogTest = FakeRuntimeTest;

TEST_F(LogTest, WarningsGoToTheHandlerAndNeverToStderr) {
  Node node{"log"};
  const std::string name = topic("log");
  ipc_shared_ptr<const Counted> kept;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{1}, [&](const ipc_shared_ptr<const Counted>& m) { kept = m; });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  auto message = publisher->borrow_loaned_message();
  publisher->publish(std::move(message));
  subscription->handle_wakeup();
  ASSERT_TRUE(kept);

  std::vector<std::pair<LogLevel, std::string>> logged;
  set_log_handler([&](LogLevel level, std::string_view text) { logged.emplace_back(level, text); });
  kernel().fail_releases(EIO);
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  kept.reset();  // the release fails where nobody can catch it
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(logged.size(), 1U);
  EXPECT_EQ(logged[0].first, LogLevel::warning);
  EXPECT_NE(logged[0].second.find("releasing a received message"), std::string::npos)
      << logged[0].second;

  set_log_handler(nullptr);
  kernel().fail_releases(0);
}

TEST_F(LogTest, WithoutAHandlerNothingIsPrinted) {
  Node node{"quiet"};
  const std::string name = topic("quiet");
  ipc_shared_ptr<const Counted> kept;
  auto subscription = node.create_subscription<Counted>(
      name, QoS{1}, [&](const ipc_shared_ptr<const Counted>& m) { kept = m; });
  auto publisher = node.create_publisher<Counted>(name, QoS{1});
  publisher->publish(publisher->borrow_loaned_message());
  subscription->handle_wakeup();
  kernel().fail_releases(EIO);
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  kept.reset();
  subscription.reset();
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  kernel().fail_releases(0);
}

}  // namespace
}  // namespace agnocast::detail
