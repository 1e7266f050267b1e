#include "agnocast/schema_service.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <future>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "agnocast/cdr.hpp"
#include "agnocast/executor.hpp"
#include "agnocast/json_to_cdr.hpp"
#include "agnocast/message_render.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_cdr.hpp"
#include "agnocast/schema_client.hpp"
#include "agnocast/service.hpp"
#include "kernel/fake_runtime.hpp"
#include "schema/schema_service_test_types.hpp"

namespace agnocast::detail {
namespace {

using schema_service_test::Sum;
using namespace std::chrono_literals;
using SchemaServiceTest = FakeRuntimeTest;
using Future = Client<Sum>::SharedFuture;

Future send(Client<Sum>& client, std::int64_t a, std::int64_t b) {
  auto request = client.borrow_loaned_request();
  request->a = a;
  request->b = b;
  return client.async_send_request(std::move(request));
}

bool ready(const Future& future) { return future.wait_for(0s) == std::future_status::ready; }

// Runs what is ready on the node until `done` or 5 s.
template <class Done>
bool spin_until(Node& node, Done done) {
  SingleThreadedExecutor executor;
  executor.add_node(node);
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (!done() && std::chrono::steady_clock::now() < deadline) executor.spin_once(10ms);
  executor.remove_node(node);
  return done();
}

TEST_F(SchemaServiceTest, AnswersACompiledClientReadingTheRequestInItsPool) {
  Node node{"schema_server"};
  const std::string name = topic("sum");
  const ServiceTypes types = service_types_of<Sum>(name);
  const void* request_seen = nullptr;
  SchemaService service(
      node, name, types, [&](SchemaMessage request, SchemaService::Responder responder) {
        request_seen = request.data();
        const std::string text = render_message_json(request.data(), types.request.schema,
                                                     {.readable = request.readable()});
        EXPECT_EQ(text, R"({"a":40,"b":2})");
        responder.send_cdr(
            json_to_cdr(R"({"sum": 42, "note": "from the schema"})", types.response.schema));
      });
  EXPECT_EQ(service.service_name(), name);
  auto client = node.create_client<Sum>(name);
  ASSERT_TRUE(client->service_is_ready());
  auto request = client->borrow_loaned_request();
  const void* request_written = request.get();
  request->a = 40;
  request->b = 2;
  Future future = client->async_send_request(std::move(request));
  ASSERT_TRUE(spin_until(node, [&] { return ready(future); }));
  EXPECT_EQ(request_seen, request_written);
  EXPECT_EQ(future.get()->sum, 42);
  EXPECT_EQ(future.get()->note, "from the schema");
  EXPECT_EQ(service.calls(), 1U);
}

TEST_F(SchemaServiceTest, AnswersLaterWithALoanOfItsOwnEvenOnceDestroyed) {
  Node node{"later"};
  const std::string name = topic("later");
  const ServiceTypes types = service_types_of<Sum>(name);
  std::vector<SchemaService::Responder> kept;
  auto service = std::make_unique<SchemaService>(
      node, name, types,
      [&](SchemaMessage, SchemaService::Responder responder) { kept.push_back(responder); });
  auto client = node.create_client<Sum>(name);
  Future first = send(*client, 1, 0);
  Future second = send(*client, 2, 0);
  ASSERT_TRUE(spin_until(node, [&] { return kept.size() == 2; }));
  EXPECT_NE(kept[0].id(), kept[1].id());
  service.reset();  // the responders keep the server
  for (int i = 1; i >= 0; --i) {
    auto* response = static_cast<Sum::Response*>(allocate_message(
        sizeof(Sum::Response), alignof(Sum::Response), &destroy_message_object<Sum::Response>));
    new (response) Sum::Response{static_cast<std::int64_t>(10 * (i + 1)), {}};
    kept[i].send(response, sizeof(Sum::Response));
  }
  ASSERT_TRUE(spin_until(node, [&] { return ready(first) && ready(second); }));
  EXPECT_EQ(first.get()->sum, 10);
  EXPECT_EQ(second.get()->sum, 20);
}

TEST_F(SchemaServiceTest, ASchemaClientAndASchemaServerTalk) {
  Node node{"schemas"};
  const std::string name = topic("schemas");
  const ServiceTypes types = service_types_of<Sum>(name);
  SchemaService service(
      node, name, types, [&](SchemaMessage request, SchemaService::Responder responder) {
        std::vector<std::uint8_t> cdr;
        serialize_with_schema(request.data(), types.request.schema, cdr,
                              {.readable = request.readable()});
        // {a, b} little-endian after the header: answer a + b.
        std::int64_t a = 0;
        std::int64_t b = 0;
        std::memcpy(&a, cdr.data() + 4, 8);
        std::memcpy(&b, cdr.data() + 12, 8);
        responder.send_cdr(
            json_to_cdr(R"({"sum": )" + std::to_string(a + b) + "}", types.response.schema));
      });
  SchemaClient client(node, name, types);
  std::optional<std::string> answer;
  client.send_cdr(json_to_cdr(R"({"a": 3, "b": 4})", types.request.schema),
                  [&](std::optional<SchemaMessage> response, std::exception_ptr error) {
                    ASSERT_FALSE(error);
                    answer = render_message_text(response->data(), types.response.schema,
                                                 {.readable = response->readable()});
                  });
  ASSERT_TRUE(spin_until(node, [&] { return answer.has_value(); }));
  EXPECT_EQ(*answer, "sum: 7\nnote: \"\"\n");
}

TEST_F(SchemaServiceTest, ResponseBytesThatAreNoResponseAreRefusedWithNothingSent) {
  Node node{"bad"};
  const std::string name = topic("bad");
  const ServiceTypes types = service_types_of<Sum>(name);
  std::vector<SchemaService::Responder> kept;
  SchemaService service(node, name, types, [&](SchemaMessage, SchemaService::Responder responder) {
    kept.push_back(responder);
  });
  auto client = node.create_client<Sum>(name);
  Future future = send(*client, 1, 1);
  ASSERT_TRUE(spin_until(node, [&] { return kept.size() == 1; }));
  EXPECT_THROW(kept[0].send_cdr(std::vector<std::uint8_t>{0, 1, 0, 0, 1}), cdr::Error);
  EXPECT_EQ(client->pending(), 1U);
}

TEST_F(SchemaServiceTest, DestroyedItFailsWhatItLeftUnanswered) {
  Node node{"stops"};
  const std::string name = topic("stops");
  const ServiceTypes types = service_types_of<Sum>(name);
  int asked = 0;
  auto service = std::make_unique<SchemaService>(
      node, name, types, [&](SchemaMessage, SchemaService::Responder) { ++asked; });
  auto client = node.create_client<Sum>(name);
  Future future = send(*client, 1, 1);
  ASSERT_TRUE(spin_until(node, [&] { return asked == 1; }));
  service.reset();
  ASSERT_TRUE(spin_until(node, [&] { return ready(future); }));
  EXPECT_THROW(future.get(), ServiceUnavailable);
}

TEST_F(SchemaServiceTest, ASecondServerOfANameIsRefused) {
  Node node{"taken"};
  const std::string name = topic("taken");
  auto first = node.create_service<Sum>(
      name, [](const ipc_shared_ptr<const Sum::Request>&, ipc_shared_ptr<Sum::Response>&) {});
  try {
    SchemaService second(node, name, service_types_of<Sum>(name),
                         [](SchemaMessage, SchemaService::Responder) {});
    FAIL() << "a second server was accepted";
  } catch (const ServiceExists& error) {
    EXPECT_NE(std::string(error.what()).find("pid " + std::to_string(::getpid())),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace agnocast::detail
