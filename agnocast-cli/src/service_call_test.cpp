// service call against a fake system: what it sends, prints and refuses, and
// its exit codes through run_cli.
#include "service_call.hpp"

#include <gtest/gtest.h>

#include <example_interfaces/srv/add_two_ints.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <std_srvs/srv/set_bool.hpp>
#include <string>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/errors.hpp"
#include "fake_source.hpp"

namespace agnocast::cli {
namespace {

using std_srvs::srv::SetBool;

// A service that appears after `absent_polls` looks and answers with `response`.
class FakeServiceBackend : public ServiceBackend {
 public:
  std::optional<ServiceTypes> types;
  int absent_polls = 0;
  CallOutcome outcome = CallOutcome::answered;
  const void* response = nullptr;  // shown as answered, readable within its object
  std::size_t response_size = 0;
  bool server_goes_away = false;

  // What the command did.
  int polls = 0;
  std::vector<std::uint8_t> sent;
  double timeout_given = -1;
  double clock = 100.0;

  std::optional<ServiceTypes> find_types(const std::string&) override {
    if (polls++ < absent_polls) return std::nullopt;
    return types;
  }
  CallOutcome call(const std::string&, const ServiceTypes&, std::span<const std::uint8_t> request,
                   double timeout_s, const Show& show) override {
    sent.assign(request.begin(), request.end());
    timeout_given = timeout_s;
    if (server_goes_away) throw ServiceUnavailable("agnocast: service /arm: the server went away");
    if (outcome == CallOutcome::answered) {
      show(response, {static_cast<const std::byte*>(response), response_size});
    }
    return outcome;
  }
  double now_seconds() override { return clock; }
  void sleep_seconds(double seconds) override { clock += seconds; }
};

class ServiceCall : public ::testing::Test {
 protected:
  void SetUp() override {
    backend_.types = service_types_of<SetBool>("/arm");
    answer_.success = true;
    answer_.message = "armed";  // short: no pool needed
    backend_.response = &answer_;
    backend_.response_size = sizeof answer_;
  }

  // The output, or the error's class and text.
  std::string run(const ServiceCallOptions& options) {
    std::ostringstream out;
    try {
      EXPECT_EQ(service_call(backend_, options, out), 0);
    } catch (const InputError& error) {
      return std::string("InputError: ") + error.what();
    } catch (const CliError& error) {
      return std::string("CliError: ") + error.what();
    }
    return out.str();
  }

  FakeServiceBackend backend_;
  SetBool::Response answer_;
};

TEST_F(ServiceCall, SendsTheJsonAsTheRequestsCdrAndPrintsTheResponseAsEchoDoes) {
  EXPECT_EQ(
      run({.service = "/arm", .type = "std_srvs/srv/SetBool", .request = R"({"data": true})"}),
      "success: true\nmessage: \"armed\"\n");
  SetBool::Request request;
  request.data = true;
  EXPECT_EQ(backend_.sent, cdr::serialize(request));
}

TEST_F(ServiceCall, JsonPrintsOneObject) {
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/SetBool", .request = "{}", .json = true}),
            "{\"success\":true,\"message\":\"armed\"}\n");
  EXPECT_EQ(backend_.sent, cdr::serialize(SetBool::Request{}));
}

TEST_F(ServiceCall, EveryStandardTypeTakesItsFields) {
  example_interfaces::srv::AddTwoInts::Response sum;
  sum.sum = 42;
  backend_.types = service_types_of<example_interfaces::srv::AddTwoInts>("/arm");
  backend_.response = &sum;
  backend_.response_size = sizeof sum;
  EXPECT_EQ(run({.service = "/arm",
                 .type = "example_interfaces/srv/AddTwoInts",
                 .request = R"({"a": 40, "b": 2})"}),
            "sum: 42\n");
  example_interfaces::srv::AddTwoInts::Request request;
  request.a = 40;
  request.b = 2;
  EXPECT_EQ(backend_.sent, cdr::serialize(request));
}

TEST_F(ServiceCall, WaitsForTheServiceToAppearWithinTheTimeout) {
  backend_.absent_polls = 10;
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .timeout_s = 1.0}),
            "success: true\nmessage: \"armed\"\n");
  EXPECT_EQ(backend_.polls, 11);
  EXPECT_NEAR(backend_.timeout_given, 0.8, 1e-9) << "what is left of the timeout";
}

TEST_F(ServiceCall, NoServiceWithinTheTimeoutIsARuntimeError) {
  backend_.absent_polls = 1'000'000;
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .timeout_s = 0.5}),
            "CliError: service '/arm' has no server (waited 0.5 s); `agnocast-cli service list` "
            "shows the services there are");
  EXPECT_NEAR(backend_.clock, 100.5, 1e-9);
  EXPECT_TRUE(backend_.sent.empty());
}

TEST_F(ServiceCall, NoServerOrNoAnswerIsARuntimeError) {
  backend_.outcome = CallOutcome::no_server;
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool"}),
            "CliError: service '/arm' has no server (waited 5 s); `agnocast-cli service list` "
            "shows the services there are");
  backend_.outcome = CallOutcome::timed_out;
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .timeout_s = 2}),
            "CliError: service '/arm' did not answer within 2 s");
  backend_.server_goes_away = true;
  ServiceCallOptions options{.service = "/arm", .type = "std_srvs/srv/SetBool"};
  std::ostringstream out;
  EXPECT_THROW(service_call(backend_, options, out), ServiceUnavailable);
}

TEST_F(ServiceCall, AnotherTypeThanTheServicesIsAUsageError) {
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/Trigger"}),
            "InputError: agnocast: service /arm has type std_srvs/srv/SetBool, not "
            "std_srvs/srv/Trigger; `agnocast-cli service type /arm` shows it");
  EXPECT_TRUE(backend_.sent.empty());
}

TEST_F(ServiceCall, JsonThatIsNoRequestOfTheTypeIsAUsageError) {
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .request = R"({"dat": true})"}),
            "InputError: the request: std_srvs/srv/SetBool_Request: unknown field \"dat\" of "
            "std_srvs/srv/SetBool_Request; its fields: data");
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .request = R"({"data": 1})"}),
            "InputError: the request: std_srvs/srv/SetBool_Request: field 'data' takes true or "
            "false, not 1");
  EXPECT_TRUE(backend_.sent.empty());
}

TEST_F(ServiceCall, BadJsonOrTypeTextIsRefusedBeforeLookingForTheService) {
  backend_.absent_polls = 1'000'000;
  EXPECT_EQ(run({.service = "/arm", .type = "std_srvs/srv/SetBool", .request = "{\"data\": tru}"})
                .rfind("InputError: the request: not JSON: ", 0),
            0U);
  EXPECT_EQ(run({.service = "/arm", .type = "SetBool"}),
            "InputError: 'SetBool' is no service type; write it as pkg/srv/Name, e.g. "
            "std_srvs/srv/SetBool");
  EXPECT_EQ(backend_.polls, 0);
}

struct Outcome {
  int code;
  std::string out;
  std::string err;
};

Outcome run_cli_with(std::vector<const char*> args) {
  FakeSource source = healthy_system();
  args.insert(args.begin(), "agnocast-cli");
  std::ostringstream out, err;
  const int code = run_cli(static_cast<int>(args.size()), args.data(), source, out, err);
  return {code, out.str(), err.str()};
}

TEST(ServiceCallCli, UsageErrorsExitTwoBeforeTouchingTheSystem) {
  const std::vector<std::vector<const char*>> usage_errors = {
      {"service"},
      {"service", "call"},
      {"service", "call", "/arm"},
      {"service", "call", "no_slash", "std_srvs/srv/SetBool"},
      {"service", "call", "/_service_request/arm", "std_srvs/srv/SetBool"},
      {"service", "call", "/arm", "std_srvs/srv/SetBool", "{"},
      {"service", "call", "/arm", "std_srvs/srv/SetBool",
       "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
       "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]"},
      {"service", "call", "/arm", "SetBool"},
      {"service", "call", "/arm", "std_srvs/srv/SetBool", "--timeout", "0"},
      {"service", "call", "/arm", "std_srvs/srv/SetBool", "--timeout", "-1"},
      {"service", "call", "/arm", "std_srvs/srv/SetBool", "{}", "extra"},
      {"service", "frobnicate"}};
  for (const auto& args : usage_errors) {
    const Outcome r = run_cli_with(args);
    EXPECT_EQ(r.code, 2) << args.size() << " words, last " << args.back() << ": " << r.err;
  }
  const Outcome unknown = run_cli_with({"service", "frobnicate"});
  EXPECT_NE(unknown.err.find("unknown command 'frobnicate' for 'agnocast-cli service'"),
            std::string::npos)
      << unknown.err;
}

TEST(ServiceCallCli, AUsageErrorWithJsonPrintsOneObject) {
  const Outcome r =
      run_cli_with({"service", "call", "/arm", "std_srvs/srv/SetBool", "{", "--json"});
  EXPECT_EQ(r.code, 2);
  const nlohmann::json value = nlohmann::json::parse(r.out);
  EXPECT_EQ(value.at("exit_code"), 2);
  EXPECT_NE(value.at("error").get<std::string>().find("not JSON"), std::string::npos);
}

}  // namespace
}  // namespace agnocast::cli
