#include "agnocast/service.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/executor.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/node.hpp"
#include "kernel/fake_runtime.hpp"
#include "schema/schema_service_test_types.hpp"

namespace agnocast::detail {
namespace {

// Sum's request adds a and b; its response's sum is what this file's
// servers answer.
using Add = schema_service_test::Sum;
using ServiceTest = FakeRuntimeTest;
using Future = Client<Add>::SharedFuture;

Future send(Client<Add>& client, std::int64_t a, std::int64_t b) {
  auto request = client.borrow_loaned_request();
  request->a = a;
  request->b = b;
  return client.async_send_request(std::move(request));
}

bool ready(const Future& future) {
  return future.wait_for(std::chrono::seconds{0}) == std::future_status::ready;
}

auto adder() {
  return [](const ipc_shared_ptr<const Add::Request>& request,
            ipc_shared_ptr<Add::Response>& response) { response->sum = request->a + request->b; };
}

TEST_F(ServiceTest, RequestAndResponseAreReadInPlaceWhereTheirSenderWroteThem) {
  Node node{"adder"};
  const std::string name = topic("add");
  const void* request_seen = nullptr;
  const void* response_written = nullptr;
  auto service =
      node.create_service<Add>(name, [&](const ipc_shared_ptr<const Add::Request>& request,
                                         ipc_shared_ptr<Add::Response>& response) {
        request_seen = request.get();
        response_written = response.get();
        response->sum = request->a + request->b;
      });
  auto client = node.create_client<Add>(name);
  ASSERT_TRUE(client->service_is_ready());

  auto request = client->borrow_loaned_request();
  const void* request_written = request.get();
  request->a = 40;
  request->b = 2;
  Future future = client->async_send_request(std::move(request));
  EXPECT_FALSE(request);
  EXPECT_FALSE(ready(future));
  EXPECT_EQ(service->handle_wakeup(), 1U);
  EXPECT_EQ(request_seen, request_written);
  EXPECT_EQ(client->handle_wakeup(), 1U);
  ASSERT_TRUE(ready(future));
  EXPECT_EQ(future.get()->sum, 42);
  EXPECT_EQ(future.get().get(), response_written);
  EXPECT_EQ(service->calls(), 1U);
  EXPECT_EQ(client->pending(), 0U);
}

TEST_F(ServiceTest, EachResponseReachesOnlyTheClientThatAsked) {
  Node node{"fan"};
  const std::string name = topic("fan");
  auto service = node.create_service<Add>(name, adder());
  std::vector<std::shared_ptr<Client<Add>>> clients;
  std::vector<Future> futures;
  for (int i = 0; i < 4; ++i) {
    clients.push_back(node.create_client<Add>(name));
    clients.back()->handle_wakeup();  // its own first notification
  }
  for (int i = 0; i < 4; ++i) futures.push_back(send(*clients[i], i, 100));
  EXPECT_EQ(service->handle_wakeup(), 4U);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(clients[i]->handle_wakeup(), 1U) << "client " << i << " gets its answer only";
    ASSERT_TRUE(ready(futures[i]));
    EXPECT_EQ(futures[i].get()->sum, 100 + i);
  }
  TopicInfo replies;
  ASSERT_TRUE(kernel().topic_info(service_reply_topic(name), replies));
  for (const auto& subscriber : replies.subscribers) EXPECT_EQ(subscriber.received, 1U);
}

TEST_F(ServiceTest, RequestsOverTheInFlightBoundAreRefusedAtTheCall) {
  Node node{"bound"};
  const std::string name = topic("bound");
  auto service = node.create_service<Add>(name, adder());
  auto client = node.create_client<Add>(name, QoS{2});
  Future first = send(*client, 1, 1);
  Future second = send(*client, 2, 2);
  EXPECT_THROW(send(*client, 3, 3), TooManyRequests);
  EXPECT_EQ(client->pending(), 2U);
  EXPECT_EQ(service->handle_wakeup(), 2U) << "the refused request was never sent";
  client->handle_wakeup();
  EXPECT_EQ(first.get()->sum, 2);
  EXPECT_EQ(second.get()->sum, 4);
  Future third = send(*client, 3, 3);  // answers free the bound
  Future fourth = send(*client, 4, 4);
  EXPECT_EQ(client->prune_pending_requests(), 2U);
  EXPECT_THROW(third.get(), std::future_error);
  EXPECT_NO_THROW(send(*client, 5, 5));
  EXPECT_EQ(service->handle_wakeup(), 3U);
  client->handle_wakeup();  // answers to pruned requests are dropped
  EXPECT_EQ(client->pending(), 0U);
}

TEST_F(ServiceTest, AFullServerQueueRejectsTheRequestInsteadOfDroppingOne) {
  Node node{"full"};
  const std::string name = topic("full");
  auto service = node.create_service<Add>(name, adder(), QoS{2});
  auto client = node.create_client<Add>(name);
  Future first = send(*client, 1, 0);
  Future second = send(*client, 2, 0);
  Future third = send(*client, 3, 0);
  ASSERT_TRUE(ready(third));
  EXPECT_THROW(third.get(), RequestRejected);
  EXPECT_EQ(service->handle_wakeup(), 2U);
  client->handle_wakeup();
  EXPECT_EQ(first.get()->sum, 1);
  EXPECT_EQ(second.get()->sum, 2);
  TopicInfo requests;
  ASSERT_TRUE(kernel().topic_info(service_request_topic(name), requests));
  ASSERT_EQ(requests.subscribers.size(), 1U);
  EXPECT_EQ(requests.subscribers[0].dropped, 0U);
}

TEST_F(ServiceTest, WithoutAServerARequestFailsAtOnce) {
  Node node{"alone"};
  auto client = node.create_client<Add>(topic("nobody"));
  EXPECT_FALSE(client->service_is_ready());
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(client->wait_for_service(std::chrono::milliseconds{30}));
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds{30});
  Future future = send(*client, 1, 2);
  ASSERT_TRUE(ready(future));
  EXPECT_THROW(future.get(), ServiceUnavailable);
  EXPECT_EQ(client->pending(), 0U);
}

TEST_F(ServiceTest, AServerDestroyedWithRequestsPendingFailsThemAndLaterOnes) {
  Node node{"stops"};
  const std::string name = topic("stops");
  auto service = node.create_service<Add>(name, adder());
  auto client = node.create_client<Add>(name);
  std::vector<Future> futures;
  for (int i = 0; i < 3; ++i) futures.push_back(send(*client, i, i));
  service.reset();
  EXPECT_EQ(client->handle_wakeup(), 1U) << "the server's last word";
  for (const auto& future : futures) {
    ASSERT_TRUE(ready(future));
    EXPECT_THROW(future.get(), ServiceUnavailable);
  }
  EXPECT_EQ(client->pending(), 0U);
  EXPECT_FALSE(client->service_is_ready());
  Future later = send(*client, 1, 1);
  ASSERT_TRUE(ready(later));
  EXPECT_THROW(later.get(), ServiceUnavailable);

  // A new server under the name serves the same client.
  auto again = node.create_service<Add>(name, adder());
  ASSERT_TRUE(client->service_is_ready());
  Future answered = send(*client, 20, 22);
  EXPECT_EQ(again->handle_wakeup(), 1U);
  client->handle_wakeup();
  EXPECT_EQ(answered.get()->sum, 42);
}

TEST_F(ServiceTest, ASecondServerOfANameIsRefusedNamingTheFirst) {
  Node node{"first"};
  const std::string name = topic("taken");
  auto service = node.create_service<Add>(name, adder());
  try {
    node.create_service<Add>(name, adder());
    FAIL() << "a second server was accepted";
  } catch (const ServiceExists& error) {
    EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("pid " + std::to_string(::getpid())),
              std::string::npos)
        << error.what();
  }
  // The refused one left nothing behind: the first still serves alone.
  TopicInfo requests;
  ASSERT_TRUE(kernel().topic_info(service_request_topic(name), requests));
  EXPECT_EQ(requests.subscribers.size(), 1U);
  auto client = node.create_client<Add>(name);
  Future future = send(*client, 1, 2);
  EXPECT_EQ(service->handle_wakeup(), 1U);
  client->handle_wakeup();
  EXPECT_EQ(future.get()->sum, 3);
}

TEST_F(ServiceTest, AClientOfAnotherResponseTypeIsRefused) {
  Node node{"types"};
  const std::string name = topic("typed");
  auto service = node.create_service<Add>(name, adder());
  EXPECT_THROW(node.create_client<schema_service_test::Wide>(name), TypeMismatch);
}

TEST_F(ServiceTest, DeferredResponsesAnswerTheRightRequestsInAnyOrder) {
  Node node{"later"};
  const std::string name = topic("later");
  std::vector<std::pair<RequestId, ipc_shared_ptr<const Add::Request>>> kept;
  std::shared_ptr<Service<Add>> server;
  server = node.create_service<Add>(name, [&](std::shared_ptr<Service<Add>> service, RequestId id,
                                              ipc_shared_ptr<const Add::Request> request) {
    EXPECT_EQ(service, server);
    kept.emplace_back(id, std::move(request));
  });
  auto client = node.create_client<Add>(name);
  std::vector<Future> futures;
  for (int i = 0; i < 3; ++i) futures.push_back(send(*client, i, 10));
  EXPECT_EQ(server->handle_wakeup(), 3U);
  ASSERT_EQ(kept.size(), 3U);
  for (auto it = kept.rbegin(); it != kept.rend(); ++it) {
    auto response = server->borrow_loaned_response();
    response->sum = it->second->a + it->second->b;
    server->send_response(it->first, std::move(response));
  }
  EXPECT_EQ(client->handle_wakeup(), 3U);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(futures[i].get()->sum, 10 + i);
}

TEST_F(ServiceTest, ThousandsOfCallsAnsweredOutOfOrderEachReachTheirOwnFuture) {
  Node node{"many"};
  const std::string name = topic("many");
  std::vector<std::pair<RequestId, ipc_shared_ptr<const Add::Request>>> kept;
  auto server = node.create_service<Add>(name, [&](std::shared_ptr<Service<Add>>, RequestId id,
                                                   ipc_shared_ptr<const Add::Request> request) {
    kept.emplace_back(id, std::move(request));
  });
  constexpr int bound = 3;
  auto client = node.create_client<Add>(name, QoS{bound});
  std::int64_t wrong = 0, answered = 0;
  for (int batch = 0; batch < 1000; ++batch) {
    // A batch fills the bound; the server answers a rotation of it, so that
    // each request's place among those in flight keeps changing.
    for (int i = 0; i < bound; ++i) {
      auto request = client->borrow_loaned_request();
      request->a = batch;
      request->b = i;
      client->async_send_request(std::move(request), [&, batch, i](Future future) {
        ++answered;
        if (future.get()->sum != batch + i) ++wrong;
      });
    }
    ASSERT_EQ(server->handle_wakeup(), static_cast<std::size_t>(bound));
    std::rotate(kept.begin(), kept.begin() + batch % bound, kept.end());
    for (auto& [id, request] : kept) {
      auto response = server->borrow_loaned_response();
      response->sum = request->a + request->b;
      server->send_response(id, std::move(response));
    }
    kept.clear();
    ASSERT_EQ(client->handle_wakeup(), static_cast<std::size_t>(bound));
  }
  EXPECT_EQ(answered, 1000 * bound);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(client->pending(), 0U);
  EXPECT_EQ(server->calls(), static_cast<std::uint64_t>(1000 * bound));
}

TEST_F(ServiceTest, AFailedRequestFailsItsFutureAloneAndLeavesNothingPending) {
  Node node{"failing"};
  const std::string name = topic("failing");
  std::vector<RequestId> kept;
  auto server = node.create_service<Add>(
      name, [&](std::shared_ptr<Service<Add>>, RequestId id, ipc_shared_ptr<const Add::Request>) {
        kept.push_back(id);
      });
  auto client = node.create_client<Add>(name);
  Future failed = send(*client, 1, 2);
  Future answered = send(*client, 3, 4);
  EXPECT_EQ(server->handle_wakeup(), 2U);
  ASSERT_EQ(kept.size(), 2U);
  server->fail_request(kept[0]);
  auto response = server->borrow_loaned_response();
  response->sum = 7;
  server->send_response(kept[1], std::move(response));
  EXPECT_EQ(client->handle_wakeup(), 2U);
  EXPECT_THROW(failed.get(), ServiceUnavailable);
  EXPECT_EQ(answered.get()->sum, 7);
  EXPECT_EQ(client->pending(), 0U);
}

TEST_F(ServiceTest, AResponseToAClientThatIsGoneIsCountedNotThrown) {
  Node node{"gone"};
  const std::string name = topic("gone_client");
  auto service = node.create_service<Add>(name, adder());
  auto client = node.create_client<Add>(name);
  Future future = send(*client, 1, 1);
  client.reset();
  EXPECT_THROW(future.get(), std::future_error);  // abandoned with its client
  EXPECT_NO_THROW(service->handle_wakeup());
  EXPECT_EQ(service->failures(), 1U);
  TopicInfo replies;
  EXPECT_FALSE(kernel().topic_info(service_reply_topic(name), replies) &&
               !replies.subscribers.empty())
      << "nothing of the client is left";
}

TEST_F(ServiceTest, ApplicationsCannotUseTheTopicsThatCarryServices) {
  Node node{"sneaky"};
  EXPECT_THROW(node.create_publisher<Add::Request>(service_request_topic(topic("x")), QoS{1}),
               std::invalid_argument);
  EXPECT_THROW(node.create_subscription<Add::Response>(service_reply_topic(topic("x")), QoS{1},
                                                       [](const Add::Response&) {}),
               std::invalid_argument);
  EXPECT_THROW(node.create_service<Add>("no_slash", adder()), std::invalid_argument);
  EXPECT_THROW(node.create_client<Add>("/_service_reply/x"), std::invalid_argument);
}

TEST_F(ServiceTest, AnExecutorRunsServerAndClientAndTheCallbackForm) {
  Node node{"spun"};
  const std::string name = topic("spun");
  auto service = node.create_service<Add>(name, adder());
  auto client = node.create_client<Add>(name);
  SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  std::promise<std::int64_t> through_callback;
  auto request = client->borrow_loaned_request();
  request->a = 5;
  request->b = 6;
  client->async_send_request(std::move(request),
                             [&](Future future) { through_callback.set_value(future.get()->sum); });
  Future future = send(*client, 7, 8);
  auto from_callback = through_callback.get_future();
  const bool answered =
      future.wait_for(std::chrono::seconds{5}) == std::future_status::ready &&
      from_callback.wait_for(std::chrono::seconds{5}) == std::future_status::ready;
  executor.cancel();
  spinner.join();
  ASSERT_TRUE(answered);
  EXPECT_EQ(future.get()->sum, 15);
  EXPECT_EQ(from_callback.get(), 11);
}

}  // namespace
}  // namespace agnocast::detail
