// agnocast-cli service call against live C++ servers in the VM: one of every
// standard service type (std_srvs Empty, Trigger, SetBool;
// example_interfaces AddTwoInts). The CLI runs in its own process, knows the
// types only from the schemas the servers registered, and prints each
// response as topic echo prints a message. Also: no server is exit 1 within
// the timeout, and a type the service does not have is exit 2.
#include <gtest/gtest.h>

#include <agnocast/agnocast.hpp>
#include <agnocast_test/process.hpp>
#include <atomic>
#include <chrono>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <nlohmann/json.hpp>
#include <std_srvs/srv/empty.hpp>
#include <std_srvs/srv/set_bool.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <string>
#include <thread>

namespace {

using agnocast_test::Outcome;
using nlohmann::json;
using namespace std::chrono_literals;
using AddTwoInts = example_interfaces::srv::AddTwoInts;
using Empty = std_srvs::srv::Empty;
using SetBool = std_srvs::srv::SetBool;
using Trigger = std_srvs::srv::Trigger;

Outcome cli(const std::string& args) {
  return agnocast_test::run_shell("agnocast-cli " + args, "service_call");
}

// A server of every standard service type, spun on a thread of its own.
class StandardServers : public ::testing::Test {
 protected:
  StandardServers()
      : empty_(node_.create_service<Empty>(
            "/svc/empty", [this](const agnocast::ipc_shared_ptr<const Empty::Request>&,
                                 agnocast::ipc_shared_ptr<Empty::Response>&) { ++emptied_; })),
        trigger_(node_.create_service<Trigger>(
            "/svc/trigger",
            [](const agnocast::ipc_shared_ptr<const Trigger::Request>&,
               agnocast::ipc_shared_ptr<Trigger::Response>& response) {
              response->success = true;
              response->message = "triggered, with a message longer than a small string";
            })),
        set_bool_(node_.create_service<SetBool>(
            "/svc/set_bool",
            [](const agnocast::ipc_shared_ptr<const SetBool::Request>& request,
               agnocast::ipc_shared_ptr<SetBool::Response>& response) {
              response->success = request->data;
              response->message = request->data ? "on" : "off";
            })),
        add_(node_.create_service<AddTwoInts>(
            "/svc/add", [](const agnocast::ipc_shared_ptr<const AddTwoInts::Request>& request,
                           agnocast::ipc_shared_ptr<AddTwoInts::Response>& response) {
              response->sum = request->a + request->b;
            })) {
    executor_.add_node(node_);
    spinner_ = std::thread([this] { executor_.spin(); });
  }
  ~StandardServers() override {
    executor_.cancel();
    spinner_.join();
  }

  agnocast::Node node_{"service_call_servers"};
  std::atomic<int> emptied_{0};
  std::shared_ptr<agnocast::Service<Empty>> empty_;
  std::shared_ptr<agnocast::Service<Trigger>> trigger_;
  std::shared_ptr<agnocast::Service<SetBool>> set_bool_;
  std::shared_ptr<agnocast::Service<AddTwoInts>> add_;
  agnocast::SingleThreadedExecutor executor_;
  std::thread spinner_;
};

TEST_F(StandardServers, EmptyAnswersAndPrintsItsOnlyField) {
  const Outcome r = cli("service call /svc/empty std_srvs/srv/Empty");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "structure_needs_at_least_one_member: 0\n");
  EXPECT_EQ(emptied_, 1);
  const Outcome with_json = cli("service call /svc/empty std_srvs/srv/Empty '{}' --json");
  ASSERT_EQ(with_json.code, 0) << with_json.err;
  EXPECT_EQ(json::parse(with_json.out), json({{"structure_needs_at_least_one_member", 0}}));
}

TEST_F(StandardServers, TriggerAnswersWithItsMessage) {
  const Outcome r = cli("service call /svc/trigger std_srvs/srv/Trigger");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "success: true\nmessage: \"triggered, with a message longer than a small string\"\n");
}

TEST_F(StandardServers, SetBoolTakesItsRequestFromJson) {
  const Outcome on = cli("service call /svc/set_bool std_srvs/srv/SetBool '{\"data\": true}'");
  ASSERT_EQ(on.code, 0) << on.err;
  EXPECT_EQ(on.out, "success: true\nmessage: \"on\"\n");
  const Outcome off =
      cli("service call /svc/set_bool std_srvs/SetBool '{\"data\": false}' --json --timeout 10");
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_EQ(json::parse(off.out), json({{"success", false}, {"message", "off"}}));
}

TEST_F(StandardServers, AddTwoIntsAddsTheFullInt64Range) {
  const Outcome r =
      cli("service call /svc/add example_interfaces/srv/AddTwoInts "
          "'{\"a\": 9223372036854775806, \"b\": 1}' --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out), json({{"sum", 9223372036854775807LL}}));
  const Outcome text =
      cli("service call /svc/add example_interfaces/srv/AddTwoInts '{\"a\": -40, \"b\": -2}'");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_EQ(text.out, "sum: -42\n");
}

TEST_F(StandardServers, ATypeTheServiceDoesNotHaveIsAUsageError) {
  const Outcome r = cli("service call /svc/set_bool std_srvs/srv/Trigger");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("has type std_srvs/srv/SetBool, not std_srvs/srv/Trigger"),
            std::string::npos)
      << r.err;
  const Outcome field = cli("service call /svc/add example_interfaces/srv/AddTwoInts '{\"c\": 1}'");
  EXPECT_EQ(field.code, 2) << field.out;
  EXPECT_NE(field.err.find("unknown field \"c\""), std::string::npos) << field.err;
  const Outcome range =
      cli("service call /svc/add example_interfaces/srv/AddTwoInts '{\"a\": 9223372036854775808}'");
  EXPECT_EQ(range.code, 2) << range.out;
}

TEST(ServiceCallLive, NoServerIsExitOneWithinTheTimeout) {
  const auto start = std::chrono::steady_clock::now();
  const Outcome r = cli("service call /svc/nobody std_srvs/srv/SetBool --timeout 1");
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.err.find("service '/svc/nobody' has no server (waited 1 s)"), std::string::npos)
      << r.err;
  EXPECT_GE(took, 1s);
  EXPECT_LT(took, 10s) << "the timeout bounds the wait";
  const Outcome with_json =
      cli("service call /svc/nobody std_srvs/srv/SetBool --timeout 0.5 --json");
  EXPECT_EQ(with_json.code, 1);
  EXPECT_EQ(json::parse(with_json.out).at("exit_code"), 1);
}

TEST(ServiceCallLive, AServerThatNeverAnswersIsExitOneAtTheTimeout) {
  agnocast::Node node{"service_call_silent"};
  std::atomic<int> asked{0};
  auto silent = node.create_service<SetBool>(
      "/svc/silent", [&](std::shared_ptr<agnocast::Service<SetBool>>, agnocast::RequestId,
                         agnocast::ipc_shared_ptr<const SetBool::Request>) { ++asked; });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  const auto start = std::chrono::steady_clock::now();
  const Outcome r = cli("service call /svc/silent std_srvs/srv/SetBool --timeout 1");
  const auto took = std::chrono::steady_clock::now() - start;
  executor.cancel();
  spinner.join();
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.err.find("did not answer within 1 s"), std::string::npos) << r.err;
  EXPECT_EQ(asked, 1);
  EXPECT_LT(took, 10s);
}

}  // namespace
