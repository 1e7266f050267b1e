// The workload lttng_events_test.py traces: a timer publishes on a first
// topic, a relay's callback publishes each message again on a second, and a
// sink counts them, all through the in-process fake kernel. Exit 0 when the
// sink received every message in order within the time limit.
// usage: agnocast_trace_workload [COUNT [--late]]
// --late: once everything is made, prints "ready" and waits for a line on
// its standard input before it publishes (a session started meanwhile).
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <new>
#include <string>

#include "agnocast/executor.hpp"
#include "agnocast/node.hpp"
#include "agnocast/publisher.hpp"
#include "agnocast/subscription.hpp"
#include "kernel/fake_kernel.hpp"
#include "kernel/runtime.hpp"

namespace {

struct Sample {
  std::uint64_t seq = 0;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace agnocast;
  using namespace std::chrono_literals;
  const std::uint64_t count = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 20;
  const bool late = argc > 2 && std::strcmp(argv[2], "--late") == 0;
  constexpr std::size_t pool_size = 4 << 20;
  auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
  detail::Runtime::install_for_testing(region, pool_size, std::make_unique<detail::FakeKernel>());

  // Queues are system-wide: names of this process only.
  const std::string prefix = "/trace_workload_" + std::to_string(::getpid());
  Node source{"source"};
  Node relay{"relay"};
  Node sink{"sink"};
  auto first = source.create_publisher<Sample>(prefix + "_a", QoS{10});
  auto second = relay.create_publisher<Sample>(prefix + "_b", QoS{10});
  auto relaying = relay.create_subscription<Sample>(
      prefix + "_a", QoS{10}, [&](const ipc_shared_ptr<const Sample>& message) {
        auto copy = second->borrow_loaned_message();
        copy->seq = message->seq;
        second->publish(std::move(copy));
      });
  std::uint64_t received = 0;
  bool in_order = true;
  auto sinking = sink.create_subscription<Sample>(prefix + "_b", QoS{10},
                                                  [&](const ipc_shared_ptr<const Sample>& message) {
                                                    in_order = in_order && message->seq == received;
                                                    ++received;
                                                  });
  std::uint64_t sent = 0;
  auto timer = source.create_wall_timer(1ms, [&] {
    if (sent == count) return;
    auto message = first->borrow_loaned_message();
    message->seq = sent++;
    first->publish(std::move(message));
  });

  SingleThreadedExecutor executor;
  executor.add_node(source);
  executor.add_node(relay);
  executor.add_node(sink);
  if (late) {
    std::cout << "ready" << std::endl;
    std::string go;
    std::getline(std::cin, go);
  }
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (received < count && std::chrono::steady_clock::now() < deadline) {
    executor.spin_once(100ms);
  }
  std::printf("published %llu, received %llu%s\n", static_cast<unsigned long long>(sent),
              static_cast<unsigned long long>(received), in_order ? "" : ", out of order");
  return received == count && in_order ? 0 : 1;
}
