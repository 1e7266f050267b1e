// Calls /add_two_ints: waits for the server, sends a request borrowed from
// this process's pool, and reads the answer in place. The executor spinning
// the client's node delivers answers; a server that goes away fails what it
// left pending, at once, with agnocast::ServiceUnavailable.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <future>

using AddTwoInts = example_interfaces::srv::AddTwoInts;
using namespace std::chrono_literals;

int main() {
  agnocast::Node node{"asker"};
  // QoS depth: at most 4 requests in flight, more throw agnocast::TooManyRequests.
  auto client = node.create_client<AddTwoInts>("/add_two_ints", agnocast::QoS{4});
  if (!client->wait_for_service(5s)) {
    std::fprintf(stderr, "no server for /add_two_ints\n");
    return 1;
  }
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);

  auto request = client->borrow_loaned_request();
  request->a = 2;
  request->b = 40;
  auto future = client->async_send_request(std::move(request));
  // Spin until the answer is there; a real program spins in its main loop.
  while (future.wait_for(0s) != std::future_status::ready) executor.spin_once(100ms);
  try {
    std::printf("2 + 40 = %lld\n", static_cast<long long>(future.get()->sum));
  } catch (const agnocast::Error& error) {  // ServiceUnavailable, RequestRejected
    std::fprintf(stderr, "not answered: %s\n", error.what());
    return 1;
  }

  // The callback form: runs from the executor once the answer is in.
  auto second = client->borrow_loaned_request();
  second->a = 1;
  second->b = 1;
  client->async_send_request(std::move(second), [&executor](auto answered) {
    std::printf("1 + 1 = %lld\n", static_cast<long long>(answered.get()->sum));
    executor.cancel();
  });
  executor.spin();
}
