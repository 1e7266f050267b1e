#include "agnocast_roles.hpp"

#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <atomic>
#include <cerrno>
#include <iostream>
#include <span>
#include <stdexcept>
#include <string>

#include "bench_support.hpp"

namespace agnocast::bench {
namespace {

// The first messages map the publisher's pool and warm caches: not measured.
constexpr std::size_t warmup_messages = 3;

struct BenchMessage {
  std::uint64_t seq = 0;
  std::int64_t t0_ns = 0;
  agnocast::vector<std::uint8_t> payload;
};

}  // namespace
}  // namespace agnocast::bench

AGNOCAST_MESSAGE(agnocast::bench::BenchMessage, "agnocast_bench/msg/BenchMessage", seq, t0_ns,
                 payload);

namespace agnocast::bench {
namespace {

std::string next_topic(const char* kind) {
  static int run = 0;
  return std::string("/bench/") + kind + "_" + std::to_string(getpid()) + "_" +
         std::to_string(run++);
}

template <typename Body>
pid_t spawn(Body body) {
  pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    int status = 1;
    try {
      status = body();
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench role: " << error.what() << "\n";
    }
    _exit(status);
  }
  return child;
}

void reap(pid_t child, const char* role) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(std::string("agnocast-bench: the ") + role + " process failed");
  }
}

void read_bytes(int fd, std::size_t count) {
  std::vector<char> bytes(count);
  if (!read_all(fd, bytes.data(), count)) throw std::runtime_error("a benchmark peer died");
}

}  // namespace

std::vector<std::vector<std::int64_t>> run_agnocast_latency(std::size_t size, std::size_t count,
                                                            std::size_t subscribers,
                                                            std::size_t scratch_bytes) {
  const std::string topic = next_topic("latency");
  const std::size_t total = warmup_messages + count;
  Pipe ready = Pipe::open(), ack = Pipe::open();
  // Subscribers count their deliveries here and only the last one acks, so
  // the benchmark's own bookkeeping does not compete with deliveries.
  void* shared = mmap(nullptr, sizeof(std::atomic<std::uint32_t>), PROT_READ | PROT_WRITE,
                      MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (shared == MAP_FAILED) throw std::runtime_error("mmap failed");
  auto* delivered = new (shared) std::atomic<std::uint32_t>(0);
  std::vector<Pipe> results;
  std::vector<pid_t> subscriber_pids;
  for (std::size_t s = 0; s < subscribers; ++s) {
    results.push_back(Pipe::open());
    int results_fd = results.back().write_fd;
    subscriber_pids.push_back(spawn([&, results_fd] {
      std::vector<std::int64_t> latencies;
      latencies.reserve(total);
      agnocast::SingleThreadedExecutor executor;
      agnocast::Node node{"bench_subscriber"};
      auto subscription = node.create_subscription<BenchMessage>(
          topic, agnocast::QoS{10}, [&](const agnocast::ipc_shared_ptr<const BenchMessage>& m) {
            std::int64_t t1 = now_ns();
            bool intact = m->payload.size() == size &&
                          payload_intact(std::span(m->payload.data(), m->payload.size()), m->seq);
            latencies.push_back(intact ? t1 - m->t0_ns : -1);
            if (delivered->fetch_add(1) + 1 == subscribers) {
              char byte = 1;
              write_all(ack.write_fd, &byte, 1);
            }
            if (latencies.size() == total) executor.cancel();
          });
      executor.add_node(node);
      char byte = 1;
      write_all(ready.write_fd, &byte, 1);
      executor.spin();
      send_latencies(results_fd, latencies);
      return 0;
    }));
  }
  pid_t publisher = spawn([&] {
    agnocast::Node node{"bench_publisher"};
    auto pub = node.create_publisher<BenchMessage>(topic, agnocast::QoS{1});
    read_bytes(ready.read_fd, subscribers);
    std::vector<std::uint8_t> scratch(scratch_bytes);
    for (std::size_t seq = 0; seq < total; ++seq) {
      auto message = pub->borrow_loaned_message();
      message->payload.resize(size);
      fill_payload(std::span(message->payload.data(), size), seq);
      fill_payload(scratch, seq);
      message->seq = seq;
      delivered->store(0);
      message->t0_ns = now_ns();
      pub->publish(std::move(message));
      read_bytes(ack.read_fd, 1);
      settle_between_messages();
    }
    return 0;
  });

  std::vector<std::vector<std::int64_t>> per_subscriber;
  for (auto& pipe : results) {
    pipe.close_write();
    std::vector<std::int64_t> latencies = receive_latencies(pipe.read_fd);
    pipe.close_read();
    if (latencies.size() != total) throw std::runtime_error("a subscriber missed messages");
    for (std::int64_t latency : latencies) {
      if (latency < 0) throw std::runtime_error("agnocast: a payload arrived corrupted");
    }
    latencies.erase(latencies.begin(), latencies.begin() + warmup_messages);
    per_subscriber.push_back(std::move(latencies));
  }
  reap(publisher, "publisher");
  for (pid_t pid : subscriber_pids) reap(pid, "subscriber");
  munmap(shared, sizeof(std::atomic<std::uint32_t>));
  return per_subscriber;
}

Throughput run_agnocast_throughput(std::size_t size, std::size_t count) {
  const std::string topic = next_topic("throughput");
  Pipe ready = Pipe::open(), report = Pipe::open();
  pid_t subscriber = spawn([&] {
    std::int64_t first_t0 = 0, last_t1 = 0;
    std::uint64_t received = 0;
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_subscriber"};
    auto subscription = node.create_subscription<BenchMessage>(
        topic, agnocast::QoS{1000}, [&](const agnocast::ipc_shared_ptr<const BenchMessage>& m) {
          if (received++ == 0) first_t0 = m->t0_ns;
          // The newest message is never dropped, so the last one always arrives.
          if (m->seq == count - 1) {
            last_t1 = now_ns();
            executor.cancel();
          }
        });
    executor.add_node(node);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    std::int64_t numbers[3] = {first_t0, last_t1, static_cast<std::int64_t>(received)};
    write_all(report.write_fd, numbers, sizeof numbers);
    return 0;
  });
  pid_t publisher = spawn([&] {
    agnocast::Node node{"bench_publisher"};
    auto pub = node.create_publisher<BenchMessage>(topic, agnocast::QoS{1});
    read_bytes(ready.read_fd, 1);
    for (std::size_t seq = 0; seq < count; ++seq) {
      auto message = pub->borrow_loaned_message();
      message->payload.resize(size);
      message->seq = seq;
      message->t0_ns = now_ns();
      pub->publish(std::move(message));
    }
    return 0;
  });
  report.close_write();
  std::int64_t numbers[3] = {};
  if (!read_all(report.read_fd, numbers, sizeof numbers)) {
    throw std::runtime_error("throughput subscriber died");
  }
  reap(publisher, "publisher");
  reap(subscriber, "subscriber");
  Throughput result;
  result.published = count;
  result.received = static_cast<std::uint64_t>(numbers[2]);
  double seconds = static_cast<double>(numbers[1] - numbers[0]) / 1e9;
  result.messages_per_s = seconds > 0 ? static_cast<double>(result.received) / seconds : 0;
  return result;
}

}  // namespace agnocast::bench
