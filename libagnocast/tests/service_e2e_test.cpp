// Services between processes against the real module (run in the VM): the
// faults a request's path can meet, each with a bound on how long anyone waits.
#include <malloc.h>

#include <agnocast/access_policy.hpp>
#include <agnocast/inspect.hpp>
#include <agnocast/naming.hpp>
#include <agnocast/service.hpp>
#include <agnocast/service_access.hpp>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <std_srvs/srv/set_bool.hpp>
#include <atomic>
#include <future>
#include <mutex>
#include <thread>

#include "e2e_support.hpp"

namespace e2e {
namespace {

using agnocast::QoS;
using agnocast_test::eventually;
using AddTwoInts = example_interfaces::srv::AddTwoInts;
using Future = agnocast::Client<AddTwoInts>::SharedFuture;

std::string unique_service(const std::string& name) { return unique_topic("srv_" + name); }

auto adder() {
  return [](const agnocast::ipc_shared_ptr<const AddTwoInts::Request>& request,
            agnocast::ipc_shared_ptr<AddTwoInts::Response>& response) {
    response->sum = request->a + request->b;
  };
}

Future send(agnocast::Client<AddTwoInts>& client, std::int64_t a, std::int64_t b) {
  auto request = client.borrow_loaned_request();
  request->a = a;
  request->b = b;
  return client.async_send_request(std::move(request));
}

bool ready(const Future& future) { return future.wait_for(0s) == std::future_status::ready; }

// The unreceived plus held entries of the service's server, as the kernel counts them.
std::uint32_t waiting_at_server(const std::string& service) {
  const auto info = agnocast::topic_info(agnocast::service_request_topic(service));
  if (!info || info->subscribers.empty()) return 0;
  return info->subscribers[0].unreceived + info->subscribers[0].held;
}

// A child that serves name and answers until told to stop.
pid_t serve_in_child(const std::string& name, Pipe& serving, Pipe& stop) {
  return fork_child([&] {
    agnocast::Node node{"adder"};
    auto service = node.create_service<AddTwoInts>(name, adder());
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    serving.send();
    std::thread stopper([&] {
      stop.receive(180s);
      executor.cancel();
    });
    executor.spin();
    stopper.join();
    return 0;
  });
}

TEST(Services, CallsAcrossProcessesAreAnsweredInOrderWithoutCopies) {
  const std::string name = unique_service("add");
  Pipe serving, stop;
  const pid_t server = serve_in_child(name, serving, stop);
  ASSERT_EQ(serving.receive(), 'x');
  agnocast::Node node{"caller"};
  auto client = node.create_client<AddTwoInts>(name);
  ASSERT_TRUE(client->wait_for_service(10s));
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::vector<Future> futures;
  for (std::int64_t i = 0; i < 50; ++i) {
    futures.push_back(send(*client, i, 1000));
    if (futures.size() % 10 == 0) {
      ASSERT_TRUE(spin_until(executor, [&] { return ready(futures.back()); }, 30s));
    }
  }
  ASSERT_TRUE(spin_until(executor, [&] { return client->pending() == 0; }, 30s));
  for (std::int64_t i = 0; i < 50; ++i) EXPECT_EQ(futures[i].get()->sum, 1000 + i);
  // The response lives in the server's pool, mapped read-only here.
  const auto pools = agnocast::list_processes();
  const auto serving_pool = std::find_if(pools.begin(), pools.end(),
                                         [&](const auto& process) { return process.pid == server; });
  ASSERT_NE(serving_pool, pools.end());
  const auto at = reinterpret_cast<std::uint64_t>(futures[0].get().get());
  EXPECT_GE(at, serving_pool->pool_addr);
  EXPECT_LT(at, serving_pool->pool_addr + serving_pool->pool_size);
  futures.clear();
  stop.send();
  EXPECT_TRUE(exited_ok(wait_child(server)));
}

TEST(Services, AServerKilledWithAHundredRequestsInFlightFailsThemAllPromptly) {
  const std::string name = unique_service("killed");
  Pipe serving, never;
  const pid_t server = fork_child([&] {
    agnocast::Node node{"hoarder"};
    std::vector<agnocast::ipc_shared_ptr<const AddTwoInts::Request>> kept;
    auto service = node.create_service<AddTwoInts>(
        name, [&](std::shared_ptr<agnocast::Service<AddTwoInts>>, agnocast::RequestId,
                  agnocast::ipc_shared_ptr<const AddTwoInts::Request> request) {
          kept.push_back(std::move(request));  // never answered
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    serving.send();
    std::thread stopper([&] {
      never.receive(180s);
      executor.cancel();
    });
    executor.spin();
    stopper.join();
    return 0;
  });
  ASSERT_EQ(serving.receive(), 'x');
  agnocast::Node node{"caller"};
  auto client = node.create_client<AddTwoInts>(name, QoS{100});
  ASSERT_TRUE(client->wait_for_service(10s));
  std::vector<Future> futures;
  for (int i = 0; i < 100; ++i) futures.push_back(send(*client, i, i));
  EXPECT_THROW(send(*client, 0, 0), agnocast::TooManyRequests);
  ASSERT_TRUE(eventually([&] { return waiting_at_server(name) == 100; }, 30s));
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin_some();
  for (const auto& future : futures) ASSERT_FALSE(ready(future));

  const auto killed_at = std::chrono::steady_clock::now();
  ::kill(server, SIGKILL);
  const bool all_failed = spin_until(
      executor,
      [&] { return std::all_of(futures.begin(), futures.end(), [](auto& f) { return ready(f); }); },
      10s);
  const auto waited = std::chrono::steady_clock::now() - killed_at;
  wait_child(server);
  ASSERT_TRUE(all_failed) << "requests still pending 10 s after their server was killed";
  std::printf("100 requests failed %.1f ms after their server was killed\n",
              std::chrono::duration<double, std::milli>(waited).count());
  for (const auto& future : futures) EXPECT_THROW(future.get(), agnocast::ServiceUnavailable);
  EXPECT_EQ(client->pending(), 0U);
  EXPECT_FALSE(client->service_is_ready());
}

TEST(Services, AClientKilledWithRequestsPendingLeavesNothingBehind) {
  const std::string name = unique_service("client_killed");
  agnocast::Node node{"keeper"};
  std::vector<std::pair<agnocast::RequestId, agnocast::ipc_shared_ptr<const AddTwoInts::Request>>>
      kept;
  auto service = node.create_service<AddTwoInts>(
      name, [&](std::shared_ptr<agnocast::Service<AddTwoInts>>, agnocast::RequestId id,
                agnocast::ipc_shared_ptr<const AddTwoInts::Request> request) {
        kept.emplace_back(id, std::move(request));
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  Pipe sent;
  const pid_t caller = fork_child([&] {
    agnocast::Node caller_node{"doomed"};
    auto client = caller_node.create_client<AddTwoInts>(name, QoS{50});
    if (!client->wait_for_service(10s)) return 1;
    std::vector<Future> futures;
    for (int i = 0; i < 50; ++i) futures.push_back(send(*client, i, i));
    sent.send();
    ::pause();
    return 0;
  });
  ASSERT_EQ(sent.receive(), 'x');
  ASSERT_TRUE(spin_until(executor, [&] { return kept.size() == 50; }, 30s));
  ::kill(caller, SIGKILL);
  wait_child(caller);
  ASSERT_TRUE(eventually(
      [&] {
        const auto replies = agnocast::topic_info(agnocast::service_reply_topic(name));
        return !replies || replies->subscribers.empty();
      },
      10s));
  for (auto& [id, request] : kept) {
    EXPECT_EQ(request->a + request->b, 2 * request->a) << "the dead client's request is intact";
    auto response = service->borrow_loaned_response();
    response->sum = request->a + request->b;
    EXPECT_NO_THROW(service->send_response(id, std::move(response)));
  }
  EXPECT_EQ(service->failures(), 50U);
  kept.clear();  // the last references to the dead client's pool
  EXPECT_TRUE(spin_until(executor, [&] {
    const auto requests = agnocast::topic_info(agnocast::service_request_topic(name));
    return requests && requests->entries == 0 && requests->publishers.empty();
  }, 10s)) << "the dead client's requests are freed once released";
  const auto replies = agnocast::topic_info(agnocast::service_reply_topic(name));
  ASSERT_TRUE(replies);
  EXPECT_EQ(replies->entries, 0U) << "no response waits for nobody";
}

TEST(Services, AThousandClientsComeAndGoAndTheServerReturnsToItsBaseline) {
  const std::string name = unique_service("churn");
  agnocast::Node node{"steady"};
  auto service = node.create_service<AddTwoInts>(name, adder());
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  // A failed assertion returns early: the spinner stops and is joined then too.
  struct StopSpinner {
    agnocast::SingleThreadedExecutor& executor;
    std::thread& spinner;
    ~StopSpinner() {
      executor.cancel();
      if (spinner.joinable()) spinner.join();
    }
  } stop_spinner{executor, spinner};
  // Each child: clients made, called once and destroyed, one after another;
  // the last child is killed holding a client with a call pending.
  const auto callers = [&](int clients, bool then_hang) {
    Pipe hanging;
    const pid_t child = fork_child([&] {
      agnocast::Node caller_node{"churner"};
      agnocast::SingleThreadedExecutor caller_executor;
      caller_executor.add_node(caller_node);
      for (int i = 0; i < clients; ++i) {
        auto client = caller_node.create_client<AddTwoInts>(name);
        if (!client->wait_for_service(10s)) return 2;
        Future future = send(*client, i, 1);
        if (!spin_until(caller_executor, [&] { return ready(future); }, 10s)) return 3;
        if (future.get()->sum != i + 1) return 4;
      }
      if (then_hang) {
        auto client = caller_node.create_client<AddTwoInts>(name);
        Future future = send(*client, 0, 0);
        hanging.send();
        ::pause();
      }
      return 0;
    });
    if (then_hang) {
      if (hanging.receive() != 'x') return false;
      ::kill(child, SIGKILL);
      wait_child(child);
      return true;
    }
    // 2: no service within 10 s; 3: no answer within 10 s; 4: a wrong one.
    const int status = wait_child(child);
    if (!exited_ok(status))
      std::printf("a child of %d callers ended with status %#x\n", clients, status);
    return exited_ok(status);
  };
  ASSERT_TRUE(callers(100, false));
  ::malloc_trim(0);
  const std::size_t baseline = ::mallinfo2().uordblks;
  for (int round = 0; round < 8; ++round) ASSERT_TRUE(callers(100, false)) << "round " << round;
  ASSERT_TRUE(callers(99, true));
  ASSERT_TRUE(callers(1, false));  // a new client after the killed one
  ASSERT_TRUE(eventually(
      [&] {
        const auto replies = agnocast::topic_info(agnocast::service_reply_topic(name));
        return replies && replies->subscribers.empty() && replies->entries <= 1;
      },
      10s));
  executor.cancel();
  spinner.join();
  ::malloc_trim(0);
  const std::size_t after = ::mallinfo2().uordblks;
  std::printf("server heap in use: %zu bytes after 100 clients, %zu after 1,001 (%+lld)\n", baseline,
              after, static_cast<long long>(after) - static_cast<long long>(baseline));
  EXPECT_LT(after, baseline + 16 * 1024) << "something per client outlived its client";
  const auto requests = agnocast::topic_info(agnocast::service_request_topic(name));
  ASSERT_TRUE(requests);
  EXPECT_TRUE(requests->publishers.empty());
  // 100 + 800 + 99 + 1 requests are calls, but for the killed client's: a
  // refusal (a failure) when its publisher was gone before the server saw
  // it, else a call whose response is a failure too if the kill came first.
  EXPECT_GE(service->calls(), 1000U);
  EXPECT_LE(service->calls(), 1001U);
  EXPECT_LE(service->failures(), 1U);
  EXPECT_GE(service->calls() + service->failures(), 1001U);
}

TEST(Services, AClientOfAnotherTypeIsRefused) {
  const std::string name = unique_service("typed");
  Pipe serving, stop;
  const pid_t server = serve_in_child(name, serving, stop);
  ASSERT_EQ(serving.receive(), 'x');
  agnocast::Node node{"wrong"};
  EXPECT_THROW(node.create_client<std_srvs::srv::SetBool>(name), agnocast::TypeMismatch);
  EXPECT_THROW(node.create_service<AddTwoInts>(name, adder()), agnocast::ServiceExists);
  stop.send();
  EXPECT_TRUE(exited_ok(wait_child(server)));
}

// A caller that names another client's reply subscriber in its request gets
// no answer sent there: the server checks that both belong to one process.
TEST(Services, ARequestNamingAnotherProcesssClientIsIgnored) {
  const std::string name = unique_service("forged");
  agnocast::Node node{"server"};
  auto service = node.create_service<AddTwoInts>(name, adder());
  agnocast::Node victim_node{"victim"};
  auto victim = victim_node.create_client<AddTwoInts>(name);
  const std::uint32_t victim_id = victim->id();
  const std::uint32_t server_queue = service->id();
  const pid_t forger = fork_child([&] {
    agnocast::Node forger_node{"forger"};
    auto own = forger_node.create_client<AddTwoInts>(name);  // a reply subscriber of its own
    agnocast::detail::PublisherCore requests(
        forger_node.state(), agnocast::service_request_topic(name), QoS{1},
        agnocast::detail::message_type_of<AddTwoInts::Request>(),
        agnocast::detail::TopicUse::service_carrier);
    auto* request = agnocast::detail::borrow_loan<AddTwoInts::Request>();
    request->a = 1;
    agnocast::detail::set_service_tag(
        request, agnocast::detail::ServiceTag{
                     1, victim_id, 0,
                     static_cast<std::uint16_t>(agnocast::detail::ServiceStatus::request)});
    requests.publish(request, sizeof *request, agnocast::detail::ServiceRoute{server_queue, true});
    return 0;
  });
  ASSERT_TRUE(exited_ok(wait_child(forger)));
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.add_node(victim_node);
  ASSERT_TRUE(spin_until(executor, [&] { return service->failures() == 1; }, 10s));
  spin_until_quiet(executor);
  EXPECT_EQ(service->calls(), 0U);
  const auto replies = agnocast::topic_info(agnocast::service_reply_topic(name));
  ASSERT_TRUE(replies);
  for (const auto& subscriber : replies->subscribers) {
    EXPECT_EQ(subscriber.received + subscriber.unreceived, 0U) << "subscriber " << subscriber.id;
  }
}

// The access policy says who may serve and who may call: here root serves and
// nobody (in group agnocast) may call but not serve.
TEST(Services, ThePolicyDecidesWhoMayServeAndWhoMayCall) {
  const std::string name = unique_service("guarded");
  agnocast::ServiceAccessRule rule;
  rule.services = name;
  rule.serve = std::vector{agnocast::AccessPrincipal{agnocast::AccessPrincipal::Kind::user, 0}};
  rule.call = std::vector{agnocast::AccessPrincipal{}};  // anyone
  agnocast::AccessPolicy policy;
  for (auto& topic_rule : agnocast::topic_rules_of(rule)) policy.rules.push_back(topic_rule);
  agnocast::set_access_policy(policy);
  Pipe serving, stop;
  const pid_t server = serve_in_child(name, serving, stop);
  const bool served = serving.receive(30s) == 'x';
  const int status = wait_child(fork_child([&] {
    if (!agnocast_test::become(65534, 65534, {agnocast_test::vm_agnocast_gid})) return 100;
    agnocast::Node node{"outsider"};
    try {
      auto rogue = node.create_service<AddTwoInts>(unique_service("guarded_other"), adder());
      auto usurper = node.create_service<AddTwoInts>(name, adder());
      return 2;  // served although only root may
    } catch (const agnocast::AccessDenied& error) {
      if (std::string(error.what()).find(name) == std::string::npos) return 3;
    }
    auto client = node.create_client<AddTwoInts>(name);
    if (!client->wait_for_service(10s)) return 4;
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);
    Future future = send(*client, 20, 22);
    if (!spin_until(executor, [&] { return ready(future); }, 10s)) return 5;
    return future.get()->sum == 42 ? 0 : 6;
  }));
  stop.send();
  wait_child(server);
  agnocast::set_access_policy(std::nullopt);
  ASSERT_TRUE(served);
  EXPECT_TRUE(exited_ok(status)) << "the step that failed: " << WEXITSTATUS(status);
}

}  // namespace
}  // namespace e2e
