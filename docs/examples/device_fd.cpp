// A driver reads its device through a file descriptor and publishes what it
// reads from the same executor that runs its timers: the descriptor's
// readiness is one more thing the executor waits for.
#include <fcntl.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>

#include "robot_messages.hpp"

int main(int argc, char** argv) {
  const char* device = argc > 1 ? argv[1] : "/dev/stdin";  // e.g. a serial port
  const int fd = ::open(device, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    std::perror(device);
    return 1;
  }
  agnocast::Node node{"lidar_driver"};
  auto publisher = node.create_publisher<robot::Scan>("/scan", agnocast::QoS{10});
  std::uint64_t seq = 0;
  agnocast::SingleThreadedExecutor executor;
  // Level-triggered: the callback must read what is there, or it runs again.
  executor.add_fd(fd, [&] {
    char buffer[4096];
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got <= 0) {  // end of file or error: stop waiting for it
      executor.remove_fd(fd);
      executor.cancel();
      return;
    }
    auto scan = publisher->borrow_loaned_message();
    scan->seq = seq++;
    scan->ranges.assign(static_cast<std::size_t>(got), 0.0F);
    for (ssize_t i = 0; i < got; ++i) scan->ranges[i] = static_cast<unsigned char>(buffer[i]);
    publisher->publish(std::move(scan));
  });
  auto heartbeat = node.create_wall_timer(std::chrono::seconds{1}, [&] {
    std::printf("%llu scans so far\n", static_cast<unsigned long long>(seq));
  });
  executor.add_node(node);
  executor.spin();
  ::close(fd);
}
