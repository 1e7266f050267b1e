#include "baselines.hpp"

#include <fcntl.h>
#include <mqueue.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace agnocast::bench {
namespace {

constexpr const char* ping_queue = "/agnocast-bench-ping";
constexpr const char* pong_queue = "/agnocast-bench-pong";

mqd_t open_queue(const char* name) {
  mq_attr attr{};
  attr.mq_maxmsg = 1;
  attr.mq_msgsize = 1;
  mqd_t queue = mq_open(name, O_RDWR | O_CREAT, 0600, &attr);
  if (queue == static_cast<mqd_t>(-1)) {
    throw std::system_error(errno, std::generic_category(), std::string("mq_open ") + name);
  }
  return queue;
}

void wait_for(pid_t child) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
}

struct SocketFrame {
  std::uint64_t seq;
  std::int64_t t0_ns;
  std::uint64_t size;
};

}  // namespace

std::vector<std::int64_t> run_mqueue_floor(std::size_t count) {
  mq_unlink(ping_queue);
  mq_unlink(pong_queue);
  mqd_t ping = open_queue(ping_queue);
  mqd_t pong = open_queue(pong_queue);
  // One way, measured like agnocast's: from the send to the receiver's return
  // from mq_receive, on the shared monotonic clock.  Half the round trip
  // would average in the pong leg, whose sender is already awake.
  const std::size_t arrivals_bytes = count * sizeof(std::int64_t);
  void* shared =
      mmap(nullptr, arrivals_bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (shared == MAP_FAILED) throw std::system_error(errno, std::generic_category(), "mmap");
  auto* arrivals = static_cast<std::int64_t*>(shared);
  pid_t echo = fork();
  if (echo == 0) {
    char byte = 0;
    for (std::size_t i = 0; i < count; ++i) {
      if (mq_receive(ping, &byte, 1, nullptr) != 1) _exit(1);
      arrivals[i] = now_ns();
      if (mq_send(pong, &byte, 1, 0) != 0) _exit(1);
    }
    _exit(0);
  }
  std::vector<std::int64_t> one_way;
  one_way.reserve(count);
  char byte = 1;
  for (std::size_t i = 0; i < count; ++i) {
    std::int64_t t0 = now_ns();
    if (mq_send(ping, &byte, 1, 0) != 0 || mq_receive(pong, &byte, 1, nullptr) != 1) {
      throw std::system_error(errno, std::generic_category(), "mqueue ping-pong");
    }
    one_way.push_back(arrivals[i] - t0);
    settle_between_messages();
  }
  wait_for(echo);
  munmap(shared, arrivals_bytes);
  mq_close(ping);
  mq_close(pong);
  mq_unlink(ping_queue);
  mq_unlink(pong_queue);
  return one_way;
}

std::vector<std::int64_t> run_unix_socket_copy(std::size_t size, std::size_t count) {
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
  std::vector<std::uint8_t> payload(size);
  for (std::size_t seq = 0; seq < count; ++seq) {
    fill_payload(payload, seq);
    SocketFrame frame{seq, now_ns(), size};
    write_all(fds[0], &frame, sizeof frame);
    write_all(fds[0], payload.data(), size);
    char ack = 0;
    read_all(fds[0], &ack, 1);
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

}  // namespace agnocast::bench
