// The agnocast side of the bridge's service test.
//
//   agnocast-bridge-test-service-node call-add-two-ints SERVICE COUNT
//   agnocast-bridge-test-service-node call-unanswered SERVICE MIN_MS MAX_MS
//   agnocast-bridge-test-service-node serve-set-bool SERVICE COUNT TIMEOUT_S
//
// call-add-two-ints calls AddTwoInts COUNT times (a = i, b = 1000 i, up to 8
// in flight; "@sent N" once the first N are sent) and exits 0 when every sum
// is right. call-unanswered sends one AddTwoInts request and exits 0 when its
// future throws ServiceUnavailable no sooner than MIN_MS and no later than
// MAX_MS after the call. serve-set-bool serves SetBool (success = data,
// message "set to true" or "set to false"), prints "@ready" once serving, and
// exits 0 after COUNT requests.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <future>
#include <std_srvs/srv/set_bool.hpp>
#include <string>
#include <vector>

namespace {

using AddTwoInts = example_interfaces::srv::AddTwoInts;
using SetBool = std_srvs::srv::SetBool;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

bool spin_until_ready(agnocast::SingleThreadedExecutor& executor,
                      const agnocast::Client<AddTwoInts>::SharedFuture& future,
                      Clock::duration limit) {
  const auto deadline = Clock::now() + limit;
  while (future.wait_for(0s) != std::future_status::ready) {
    if (Clock::now() >= deadline) return false;
    executor.spin_once(10ms);
  }
  return true;
}

int call_add_two_ints(const std::string& service, std::uint32_t count) {
  agnocast::Node node("bridge_test_caller");
  auto client = node.create_client<AddTwoInts>(service, agnocast::QoS(8));
  if (!client->wait_for_service(60s)) {
    std::fprintf(stderr, "agnocast-bridge-test-service-node: no server for %s\n", service.c_str());
    return 1;
  }
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::deque<std::pair<std::uint32_t, agnocast::Client<AddTwoInts>::SharedFuture>> in_flight;
  std::uint32_t sent = 0, right = 0, wrong = 0;
  bool announced = false;
  while (right + wrong < count) {
    while (sent < count && in_flight.size() < 8) {
      auto request = client->borrow_loaned_request();
      request->a = sent;
      request->b = 1000LL * sent;
      in_flight.emplace_back(sent++, client->async_send_request(std::move(request)));
    }
    if (!announced) {  // for a test that starts the server only then
      std::printf("@sent %zu\n", in_flight.size());
      std::fflush(stdout);
      announced = true;
    }
    auto [i, future] = in_flight.front();
    in_flight.pop_front();
    if (!spin_until_ready(executor, future, 30s)) {
      std::fprintf(stderr, "agnocast-bridge-test-service-node: call %u not answered\n", i);
      return 1;
    }
    try {
      ++(future.get()->sum == 1001LL * i ? right : wrong);
    } catch (const agnocast::Error& error) {
      std::fprintf(stderr, "agnocast-bridge-test-service-node: call %u failed: %s\n", i,
                   error.what());
      ++wrong;
    }
  }
  std::printf("agnocast-bridge-test-service-node: %s: %u of %u sums right, %u wrong\n",
              service.c_str(), right, count, wrong);
  return right == count ? 0 : 1;
}

int call_unanswered(const std::string& service, long min_ms, long max_ms) {
  agnocast::Node node("bridge_test_caller");
  auto client = node.create_client<AddTwoInts>(service);
  if (!client->wait_for_service(60s)) {
    std::fprintf(stderr, "agnocast-bridge-test-service-node: no server for %s\n", service.c_str());
    return 1;
  }
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  auto request = client->borrow_loaned_request();
  request->a = 1;
  request->b = 2;
  const auto start = Clock::now();
  auto future = client->async_send_request(std::move(request));
  const bool ready = spin_until_ready(executor, future, std::chrono::milliseconds(max_ms) + 5s);
  const auto elapsed =
      std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count();
  if (!ready) {
    std::fprintf(stderr, "agnocast-bridge-test-service-node: %s: still pending after %ld ms\n",
                 service.c_str(), static_cast<long>(elapsed));
    return 1;
  }
  try {
    future.get();
    std::fprintf(stderr, "agnocast-bridge-test-service-node: %s: answered\n", service.c_str());
    return 1;
  } catch (const agnocast::ServiceUnavailable& error) {
    std::printf("agnocast-bridge-test-service-node: %s: failed after %ld ms: %s\n", service.c_str(),
                static_cast<long>(elapsed), error.what());
  }
  if (client->prune_pending_requests() != 0) {
    std::fprintf(stderr, "agnocast-bridge-test-service-node: a request stayed pending\n");
    return 1;
  }
  return elapsed >= min_ms && elapsed <= max_ms ? 0 : 1;
}

int serve_set_bool(const std::string& service, std::uint32_t count, double timeout_s) {
  agnocast::Node node("bridge_test_server");
  std::uint32_t served = 0;
  auto server = node.create_service<SetBool>(
      service, [&served](const agnocast::ipc_shared_ptr<const SetBool::Request>& request,
                         agnocast::ipc_shared_ptr<SetBool::Response>& response) {
        response->success = request->data;
        response->message = request->data ? "set to true" : "set to false";
        ++served;
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::printf("@ready\n");
  std::fflush(stdout);
  const auto deadline =
      Clock::now() + std::chrono::milliseconds(static_cast<long>(timeout_s * 1000));
  while (served < count && Clock::now() < deadline) executor.spin_once(50ms);
  // The last responses are published: let the bridge take them before this
  // server goes (its going would fail what it has not answered).
  const auto linger = Clock::now() + 1s;
  while (Clock::now() < linger) executor.spin_once(50ms);
  std::printf("agnocast-bridge-test-service-node: %s: served %u of %u\n", service.c_str(), served,
              count);
  return served == count ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 3 && args[0] == "call-add-two-ints") {
    return call_add_two_ints(args[1], std::stoul(args[2]));
  }
  if (args.size() == 4 && args[0] == "call-unanswered") {
    return call_unanswered(args[1], std::stol(args[2]), std::stol(args[3]));
  }
  if (args.size() == 4 && args[0] == "serve-set-bool") {
    return serve_set_bool(args[1], std::stoul(args[2]), std::stod(args[3]));
  }
  std::fprintf(stderr,
               "usage: agnocast-bridge-test-service-node call-add-two-ints|call-unanswered|"
               "serve-set-bool SERVICE ...\n");
  return 2;
}
