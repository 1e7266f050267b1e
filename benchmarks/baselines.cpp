#include "baselines.hpp"

#include <fcntl.h>
#include <mqueue.h>
#include <sys/epoll.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "window_counters.hpp"

namespace agnocast::bench {
namespace {

std::string queue_name(const char* role, std::size_t index = 0) {
  return "/agnocast-bench-" + std::to_string(getpid()) + "-" + role + "-" + std::to_string(index);
}

mqd_t open_queue(const std::string& name) {
  mq_attr attr{};
  attr.mq_maxmsg = 1;
  attr.mq_msgsize = 1;
  mqd_t queue = mq_open(name.c_str(), O_RDWR | O_CREAT, 0600, &attr);
  if (queue == static_cast<mqd_t>(-1)) {
    throw std::system_error(errno, std::generic_category(), "mq_open " + name);
  }
  return queue;
}

void wait_for(pid_t child) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("a baseline's receiver process failed");
  }
}

// A receiver that sleeps the way `wait` says, then takes the message.
class FloorReceiver {
 public:
  FloorReceiver(mqd_t queue, FloorWait wait) : queue_(queue) {
    if (wait == FloorWait::blocking) return;
    epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
    epoll_event event{};
    event.events = EPOLLIN;
    if (epoll_fd_ < 0 || epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, queue, &event) != 0) {
      throw std::system_error(errno, std::generic_category(), "epoll for the floor");
    }
  }
  bool receive() const {
    epoll_event event{};
    if (epoll_fd_ >= 0) {
      while (epoll_wait(epoll_fd_, &event, 1, -1) != 1) {
        if (errno != EINTR) return false;
      }
    }
    char byte = 0;
    return mq_receive(queue_, &byte, 1, nullptr) == 1;
  }

 private:
  mqd_t queue_;
  int epoll_fd_ = -1;
};

template <typename T>
T* map_shared(std::size_t count) {
  void* memory =
      mmap(nullptr, count * sizeof(T), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (memory == MAP_FAILED) throw std::system_error(errno, std::generic_category(), "mmap");
  return static_cast<T*>(memory);
}

struct SocketFrame {
  std::uint64_t seq;
  std::int64_t t0_ns;
  std::uint64_t size;
};

}  // namespace

std::vector<std::int64_t> run_mqueue_floor(std::size_t count, FloorWait wait,
                                           std::size_t scratch_bytes) {
  const std::string ping_name = queue_name("ping"), pong_name = queue_name("pong");
  mqd_t ping = open_queue(ping_name);
  mqd_t pong = open_queue(pong_name);
  // One way, measured like agnocast's: from the send to the receiver's return
  // from mq_receive, on the shared monotonic clock.  Half the round trip
  // would average in the pong leg, whose sender is already awake.
  auto* arrivals = map_shared<std::int64_t>(count);
  pid_t echo = fork();
  if (echo == 0) {
    FloorReceiver receiver(ping, wait);
    char byte = 0;
    for (std::size_t i = 0; i < count; ++i) {
      if (!receiver.receive()) _exit(1);
      arrivals[i] = now_ns();
      if (mq_send(pong, &byte, 1, 0) != 0) _exit(1);
    }
    _exit(0);
  }
  std::vector<std::int64_t> one_way;
  one_way.reserve(count);
  SharedScratch scratch(scratch_bytes);
  SampleWindows windows(
      std::string(wait == FloorWait::epoll ? "mqueue_epoll_floor" : "mqueue_floor") +
      " size=1 scratch=" + std::to_string(scratch_bytes));
  char byte = 1;
  for (std::size_t i = 0; i < count; ++i) {
    fill_payload(scratch.bytes(), i);
    windows.before_send();
    std::int64_t t0 = now_ns();
    const bool sent = mq_send(ping, &byte, 1, 0) == 0;
    windows.sent();
    if (!sent || mq_receive(pong, &byte, 1, nullptr) != 1) {
      throw std::system_error(errno, std::generic_category(), "mqueue ping-pong");
    }
    windows.after_ack(i);
    one_way.push_back(arrivals[i] - t0);
    settle_between_messages();
  }
  wait_for(echo);
  munmap(arrivals, count * sizeof(std::int64_t));
  mq_close(ping);
  mq_close(pong);
  mq_unlink(ping_name.c_str());
  mq_unlink(pong_name.c_str());
  return one_way;
}

std::vector<std::int64_t> run_mqueue_fanout(std::size_t receivers, std::size_t count) {
  std::vector<std::string> names;
  std::vector<mqd_t> queues;
  for (std::size_t r = 0; r < receivers; ++r) {
    names.push_back(queue_name("fanout", r));
    queues.push_back(open_queue(names.back()));
  }
  auto* arrivals = map_shared<std::int64_t>(receivers);
  auto* delivered = new (map_shared<std::atomic<std::uint32_t>>(1)) std::atomic<std::uint32_t>(0);
  Pipe ack = Pipe::open();
  std::vector<pid_t> children;
  for (std::size_t r = 0; r < receivers; ++r) {
    pid_t child = fork();
    if (child == 0) {
      FloorReceiver receiver(queues[r], FloorWait::epoll);
      for (std::size_t i = 0; i < count; ++i) {
        if (!receiver.receive()) _exit(1);
        arrivals[r] = now_ns();
        if (delivered->fetch_add(1) + 1 == receivers) {
          char byte = 1;
          write_all(ack.write_fd, &byte, 1);
        }
      }
      _exit(0);
    }
    children.push_back(child);
  }
  std::vector<std::int64_t> last_delivery;
  char byte = 1;
  for (std::size_t i = 0; i < count; ++i) {
    delivered->store(0);
    const std::int64_t t0 = now_ns();
    for (mqd_t queue : queues) {
      if (mq_send(queue, &byte, 1, 0) != 0) {
        throw std::system_error(errno, std::generic_category(), "mqueue fan-out");
      }
    }
    if (!read_all(ack.read_fd, &byte, 1)) throw std::runtime_error("a fan-out receiver died");
    std::int64_t last = 0;
    for (std::size_t r = 0; r < receivers; ++r) last = std::max(last, arrivals[r]);
    last_delivery.push_back(last - t0);
    settle_between_messages();
  }
  for (pid_t child : children) wait_for(child);
  for (std::size_t r = 0; r < receivers; ++r) {
    mq_close(queues[r]);
    mq_unlink(names[r].c_str());
  }
  munmap(arrivals, receivers * sizeof(std::int64_t));
  munmap(delivered, sizeof(std::atomic<std::uint32_t>));
  ack.close_read();
  ack.close_write();
  return last_delivery;
}

std::vector<std::int64_t> run_unix_socket_copy(std::size_t size, std::size_t count,
                                               std::size_t scratch_bytes) {
  int fds[2];
  if (socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) {
    throw std::system_error(errno, std::generic_category(), "socketpair");
  }
  Pipe results = Pipe::open();
  pid_t receiver = fork();
  if (receiver == 0) {
    close(fds[0]);
    results.close_read();
    std::vector<std::uint8_t> buffer(size);
    std::vector<std::int64_t> latencies;
    SocketFrame frame{};
    while (read_all(fds[1], &frame, sizeof frame)) {
      read_all(fds[1], buffer.data(), frame.size);
      std::int64_t latency = now_ns() - frame.t0_ns;
      bool intact = payload_intact(buffer, frame.seq);
      latencies.push_back(intact ? latency : -1);
      char ack = 1;
      write_all(fds[1], &ack, 1);
    }
    send_latencies(results.write_fd, latencies);
    _exit(0);
  }
  close(fds[1]);
  results.close_write();
  std::vector<std::uint8_t> payload(size), scratch(scratch_bytes);
  SampleWindows windows("unix_socket size=" + std::to_string(size) +
                        " scratch=" + std::to_string(scratch_bytes));
  for (std::size_t seq = 0; seq < count; ++seq) {
    fill_payload(payload, seq);
    fill_payload(scratch, seq);
    windows.before_send();
    SocketFrame frame{seq, now_ns(), size};
    write_all(fds[0], &frame, sizeof frame);
    write_all(fds[0], payload.data(), size);
    windows.sent();
    char ack = 0;
    read_all(fds[0], &ack, 1);
    windows.after_ack(seq);
    settle_between_messages();
  }
  close(fds[0]);
  std::vector<std::int64_t> latencies = receive_latencies(results.read_fd);
  results.close_read();
  wait_for(receiver);
  for (std::int64_t latency : latencies) {
    if (latency < 0) throw std::runtime_error("unix socket baseline: a payload arrived corrupted");
  }
  return latencies;
}

std::vector<std::int64_t> run_unix_socket_request_response(std::size_t count) {
  int fds[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::system_error(errno, std::generic_category(), "socketpair");
  }
  // Sleeps in epoll_wait until fd is readable, then reads its one byte;
  // false at the peer's end.
  auto wait_and_read = [](int epoll_fd, int fd) {
    epoll_event event{};
    while (epoll_wait(epoll_fd, &event, 1, -1) != 1) {
      if (errno != EINTR) return false;
    }
    char byte = 0;
    return ::read(fd, &byte, 1) == 1;
  };
  auto epoll_on = [](int fd) {
    const int epoll_fd = epoll_create1(EPOLL_CLOEXEC);
    epoll_event event{};
    event.events = EPOLLIN;
    if (epoll_fd < 0 || epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &event) != 0) {
      throw std::system_error(errno, std::generic_category(), "epoll for the socket floor");
    }
    return epoll_fd;
  };
  const pid_t server = fork();
  if (server < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (server == 0) {
    ::close(fds[0]);
    const int epoll_fd = epoll_on(fds[1]);
    const char answer = 2;
    while (wait_and_read(epoll_fd, fds[1])) {
      if (::write(fds[1], &answer, 1) != 1) _exit(1);
    }
    _exit(0);
  }
  ::close(fds[1]);
  const int epoll_fd = epoll_on(fds[0]);
  std::vector<std::int64_t> round_trips;
  const char request = 1;
  for (std::size_t i = 0; i < count; ++i) {
    settle_between_messages();
    const std::int64_t t0 = now_ns();
    if (::write(fds[0], &request, 1) != 1 || !wait_and_read(epoll_fd, fds[0])) {
      throw std::system_error(errno, std::generic_category(), "socket request/response");
    }
    round_trips.push_back(now_ns() - t0);
  }
  ::close(epoll_fd);
  ::close(fds[0]);
  wait_for(server);
  return round_trips;
}

CpuPerMessage run_mqueue_floor_cpu(std::size_t count) {
  const std::string name = queue_name("cpu");
  mqd_t queue = open_queue(name);
  Pipe ready = Pipe::open(), report = Pipe::open();
  const std::size_t total = steady_warmup_messages + count;
  pid_t child = fork();
  if (child == 0) {
    FloorReceiver receiver(queue, FloorWait::epoll);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    std::int64_t cpu0 = 0;
    for (std::size_t i = 0; i < total; ++i) {
      if (!receiver.receive()) _exit(1);
      if (i + 1 == steady_warmup_messages) cpu0 = cpu_time_ns();
    }
    const std::int64_t used = cpu_time_ns() - cpu0;
    write_all(report.write_fd, &used, sizeof used);
    _exit(0);
  }
  char byte = 1;
  if (!read_all(ready.read_fd, &byte, 1)) throw std::runtime_error("floor receiver died");
  std::int64_t cpu0 = 0;
  std::int64_t next = now_ns();
  for (std::size_t i = 0; i < total; ++i) {
    next += steady_period_ns;
    sleep_until_ns(next);
    if (mq_send(queue, &byte, 1, 0) != 0) {
      throw std::system_error(errno, std::generic_category(), "floor mq_send");
    }
    if (i + 1 == steady_warmup_messages) cpu0 = cpu_time_ns();
  }
  const std::int64_t publisher_used = cpu_time_ns() - cpu0;
  std::int64_t subscriber_used = 0;
  if (!read_all(report.read_fd, &subscriber_used, sizeof subscriber_used)) {
    throw std::runtime_error("floor receiver died");
  }
  wait_for(child);
  mq_close(queue);
  mq_unlink(name.c_str());
  return per_message(publisher_used, subscriber_used, count);
}

}  // namespace agnocast::bench
