#include "agnocast/schema_client.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/executor.hpp"
#include "agnocast/json_to_cdr.hpp"
#include "agnocast/message_render.hpp"
#include "agnocast/node.hpp"
#include "agnocast/service.hpp"
#include "kernel/fake_runtime.hpp"
#include "schema/schema_service_test_types.hpp"

namespace agnocast::detail {
namespace {

using schema_service_test::Sum;
using namespace std::chrono_literals;
using SchemaClientTest = FakeRuntimeTest;

// The request {a, b} as XCDR1.
std::vector<std::uint8_t> request_cdr(const ServiceTypes& types, std::int64_t a, std::int64_t b) {
  return json_to_cdr(R"({"a": )" + std::to_string(a) + R"(, "b": )" + std::to_string(b) + "}",
                     types.request.schema);
}

auto adder() {
  return [](const ipc_shared_ptr<const Sum::Request>& request,
            ipc_shared_ptr<Sum::Response>& response) {
    response->sum = request->a + request->b;
    response->note = "added";
  };
}

std::string text_of(const SchemaMessage& response, const ServiceTypes& types) {
  return render_message_text(response.data(), types.response.schema,
                             {.readable = response.readable()});
}

// Spins `node` on a thread of its own while alive.
class Spinning {
 public:
  explicit Spinning(Node& node) {
    executor_.add_node(node);
    thread_ = std::thread([this] { executor_.spin(); });
  }
  ~Spinning() {
    executor_.cancel();
    thread_.join();
  }

 private:
  SingleThreadedExecutor executor_;
  std::thread thread_;
};

TEST_F(SchemaClientTest, CallsACompiledServerAndReadsTheResponseInItsPool) {
  Node server_node{"sum_server"};
  Node client_node{"schema_client"};
  const std::string name = topic("sum");
  const void* written = nullptr;
  auto service =
      server_node.create_service<Sum>(name, [&](const ipc_shared_ptr<const Sum::Request>& request,
                                                ipc_shared_ptr<Sum::Response>& response) {
        written = response.get();
        response->sum = request->a + request->b;
        response->note = "a note longer than any small-string buffer";
      });
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(client_node, name, types);
  EXPECT_EQ(client.service_name(), name);
  ASSERT_TRUE(client.service_is_ready());
  const Spinning server(server_node);
  // No executor spins the client's node: call() receives the answer itself.
  const std::optional<SchemaMessage> response = client.call_cdr(request_cdr(types, 40, 2), 10s);
  ASSERT_TRUE(response);
  EXPECT_EQ(response->data(), written);
  EXPECT_EQ(text_of(*response, types),
            "sum: 42\nnote: \"a note longer than any small-string buffer\"\n");
  EXPECT_EQ(client.pending(), 0U);
}

TEST_F(SchemaClientTest, CallReturnsWhenAnExecutorSpinningTheClientGotTheAnswer) {
  Node node{"both"};
  const std::string name = topic("both");
  auto service = node.create_service<Sum>(name, adder());
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types);
  const Spinning spinning(node);
  for (int i = 0; i < 20; ++i) {
    const auto response = client.call_cdr(request_cdr(types, i, 1), 10s);
    ASSERT_TRUE(response) << "call " << i;
    EXPECT_EQ(text_of(*response, types), "sum: " + std::to_string(i + 1) + "\nnote: \"added\"\n");
  }
}

TEST_F(SchemaClientTest, SendsAsynchronouslyThroughTheExecutor) {
  Node node{"async"};
  const std::string name = topic("async");
  auto service = node.create_service<Sum>(name, adder());
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types);
  std::promise<std::string> answered;
  client.send_cdr(request_cdr(types, 5, 6),
                  [&](std::optional<SchemaMessage> response, std::exception_ptr error) {
                    ASSERT_FALSE(error);
                    answered.set_value(text_of(*response, types));
                  });
  const Spinning spinning(node);
  auto text = answered.get_future();
  ASSERT_EQ(text.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(text.get(), "sum: 11\nnote: \"added\"\n");
}

TEST_F(SchemaClientTest, WithoutAServerTheCallFailsAtOnce) {
  Node node{"alone"};
  const std::string name = topic("nobody");
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types);
  EXPECT_FALSE(client.wait_for_service(20ms));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(client.call_cdr(request_cdr(types, 1, 2), 10s), ServiceUnavailable);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_EQ(client.pending(), 0U);
}

TEST_F(SchemaClientTest, AnUnansweredCallTimesOutAndIsForgotten) {
  Node node{"silent"};
  const std::string name = topic("silent");
  std::vector<RequestId> ignored;
  auto service = node.create_service<Sum>(
      name, [&](std::shared_ptr<Service<Sum>>, RequestId id, ipc_shared_ptr<const Sum::Request>) {
        ignored.push_back(id);
      });
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(client.call_cdr(request_cdr(types, 1, 1), 50ms));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);
  EXPECT_EQ(client.pending(), 0U);
  // An answer coming later finds nobody waiting, and is dropped.
  EXPECT_EQ(service->handle_wakeup(), 1U);
  ASSERT_EQ(ignored.size(), 1U);
  service->send_response(ignored[0], service->borrow_loaned_response());
  EXPECT_FALSE(client.forget(ignored[0]));
}

TEST_F(SchemaClientTest, BytesThatAreNoRequestAreRefusedWithNothingSent) {
  Node node{"bad_bytes"};
  const std::string name = topic("bad_bytes");
  auto service = node.create_service<Sum>(name, adder());
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types);
  const std::vector<std::uint8_t> short_cdr{0x00, 0x01, 0x00, 0x00, 1, 2, 3};
  EXPECT_THROW(client.send_cdr(short_cdr, [](auto, auto) {}), cdr::Error);
  EXPECT_THROW(client.call_cdr(std::vector<std::uint8_t>{1, 2}, 1s), cdr::Error);
  EXPECT_EQ(client.pending(), 0U);
  EXPECT_EQ(service->handle_wakeup(), 0U);
}

TEST_F(SchemaClientTest, RequestsOverTheInFlightBoundAreRefusedAtTheCall) {
  Node node{"bound"};
  const std::string name = topic("bound");
  auto service = node.create_service<Sum>(name, adder());
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaClient client(node, name, types, QoS{1});
  client.send_cdr(request_cdr(types, 1, 1), [](auto, auto) {});
  EXPECT_THROW(client.send_cdr(request_cdr(types, 2, 2), [](auto, auto) {}), TooManyRequests);
  EXPECT_EQ(client.prune_pending(), 1U);
  EXPECT_EQ(service->handle_wakeup(), 1U);
}

TEST_F(SchemaClientTest, AServerOfOtherTypesIsRefused) {
  Node node{"other"};
  const std::string name = topic("other");
  auto service = node.create_service<Sum>(name, adder());
  ServiceTypes types = service_types_of<Sum>(name);
  types.response = service_types_of<schema_service_test::Wide>(name).response;
  EXPECT_THROW((SchemaClient{node, name, types}), TypeMismatch);
}

}  // namespace
}  // namespace agnocast::detail
