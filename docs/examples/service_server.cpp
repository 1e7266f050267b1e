// Serves /add_two_ints: each request is read in place in the caller's pool,
// each response is filled in this process's pool and read in place by the
// one caller that asked. A second service answers later: it keeps each
// request and answers from a timer, as a server that waits for hardware does.
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <deque>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <utility>

using AddTwoInts = example_interfaces::srv::AddTwoInts;
using Trigger = std_srvs::srv::Trigger;

int main() {
  agnocast::Node node{"calculator"};
  auto adder = node.create_service<AddTwoInts>(
      "/add_two_ints", [](const agnocast::ipc_shared_ptr<const AddTwoInts::Request>& request,
                          agnocast::ipc_shared_ptr<AddTwoInts::Response>& response) {
        response->sum = request->a + request->b;
      });

  // Deferred: the callback keeps the request id; the timer answers.
  std::deque<agnocast::RequestId> waiting;
  auto calibrate = node.create_service<Trigger>(
      "/calibrate", [&waiting](std::shared_ptr<agnocast::Service<Trigger>>, agnocast::RequestId id,
                               agnocast::ipc_shared_ptr<const Trigger::Request>) {
        waiting.push_back(id);
      });
  auto finish = node.create_wall_timer(std::chrono::milliseconds{200}, [&] {
    if (waiting.empty()) return;
    auto response = calibrate->borrow_loaned_response();
    response->success = true;
    response->message = "calibrated";
    calibrate->send_response(waiting.front(), std::move(response));
    waiting.pop_front();
  });

  std::printf("serving /add_two_ints and /calibrate\n");
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  executor.spin();  // until SIGINT or SIGTERM
}
