#include "agnocast_roles.hpp"

#include <sys/mman.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "allocation_counter.hpp"
#include "bench_service.hpp"
#include "bench_support.hpp"
#include "syscall_counter.hpp"
#include "window_counters.hpp"

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
                                                            const LatencyOptions& options) {
  const std::string topic = options.topic.empty() ? next_topic("latency") : options.topic;
  const std::size_t scratch_bytes = options.scratch_bytes;
  const agnocast::QoS publisher_qos{options.depth.value_or(1)};
  const agnocast::QoS subscriber_qos{options.depth.value_or(10)};
  const std::size_t total = warmup_messages + count;
  // With several subscribers only the last delivery counts, and on one vCPU
  // (icount) every earlier subscriber's work before it sleeps delays it: so
  // each keeps the message and checks its payload only once all have it,
  // when the publisher says so on a second topic.
  const bool check_after_window = subscribers > 1;
  const std::string check_topic = topic + "_check";
  Pipe ready = Pipe::open(), ack = Pipe::open();
  // Subscribers count their deliveries here and only the last one acks, so
  // the benchmark's own bookkeeping does not compete with deliveries.
  void* shared = mmap(nullptr, sizeof(std::atomic<std::uint32_t>), PROT_READ | PROT_WRITE,
                      MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (shared == MAP_FAILED) throw std::runtime_error("mmap failed");
  auto* delivered = new (shared) std::atomic<std::uint32_t>(0);
  auto last_one_acks = [&] {
    if (delivered->fetch_add(1) + 1 == subscribers) {
      char byte = 1;
      write_all(ack.write_fd, &byte, 1);
    }
  };
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
      auto record = [&](const BenchMessage& m, std::int64_t latency) {
        bool intact = m.payload.size() == size &&
                      payload_intact(std::span(m.payload.data(), m.payload.size()), m.seq);
        latencies.push_back(intact ? latency : -1);
        if (latencies.size() == total) executor.cancel();
      };
      agnocast::ipc_shared_ptr<const BenchMessage> unchecked;
      std::int64_t unchecked_latency = 0;
      auto subscription = node.create_subscription<BenchMessage>(
          topic, subscriber_qos, [&](const agnocast::ipc_shared_ptr<const BenchMessage>& m) {
            std::int64_t t1 = now_ns();
            if (check_after_window) {
              unchecked = m;
              unchecked_latency = t1 - m->t0_ns;
              last_one_acks();
              return;
            }
            record(*m, t1 - m->t0_ns);
            last_one_acks();
          });
      std::shared_ptr<agnocast::Subscription<BenchMessage>> check;
      if (check_after_window) {
        check = node.create_subscription<BenchMessage>(
            check_topic, agnocast::QoS{10},
            [&](const agnocast::ipc_shared_ptr<const BenchMessage>&) {
              if (!unchecked) throw std::runtime_error("a check came before its message");
              record(*unchecked, unchecked_latency);
              unchecked.reset();
              last_one_acks();
            });
      }
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
    auto pub = node.create_publisher<BenchMessage>(topic, publisher_qos);
    std::shared_ptr<agnocast::Publisher<BenchMessage>> check;
    if (check_after_window)
      check = node.create_publisher<BenchMessage>(check_topic, agnocast::QoS{1});
    read_bytes(ready.read_fd, subscribers);
    SharedScratch scratch(scratch_bytes);
    SampleWindows windows("agnocast size=" + std::to_string(size) +
                          " scratch=" + std::to_string(scratch_bytes));
    for (std::size_t seq = 0; seq < total; ++seq) {
      auto message = pub->borrow_loaned_message();
      message->payload.resize(size);
      fill_payload(std::span(message->payload.data(), size), seq);
      fill_payload(scratch.bytes(), seq);
      message->seq = seq;
      delivered->store(0);
      windows.before_send();
      message->t0_ns = now_ns();
      pub->publish(std::move(message));
      windows.sent();
      read_bytes(ack.read_fd, 1);
      windows.after_ack(seq);
      if (check) {
        delivered->store(0);
        check->publish(check->borrow_loaned_message());
        read_bytes(ack.read_fd, 1);
      }
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

std::vector<std::int64_t> run_agnocast_publish_call(std::size_t depth, std::size_t subscribers,
                                                    std::size_t count, bool queue_full) {
  if (!queue_full && subscribers != 1) {
    throw std::invalid_argument("a queue that is never full has one subscriber here");
  }
  const std::string topic = next_topic("publish_call");
  const agnocast::QoS qos{depth};
  // Up to 1,000 subscribers in the publisher's process, the rest in others.
  const std::size_t local = std::min<std::size_t>(subscribers, 1000);
  const IdleEndpoints others =
      IdleEndpoints::polling_subscribers_of(topic, subscribers - local, depth);
  Pipe results = Pipe::open();
  pid_t publisher = spawn([&] {
    agnocast::Node node{"bench_publish_call"};
    std::vector<std::shared_ptr<agnocast::PollingSubscriber<BenchMessage>>> polling;
    for (std::size_t s = 0; s < local; ++s) {
      polling.push_back(node.create_polling_subscriber<BenchMessage>(topic, qos));
    }
    auto pub = node.create_publisher<BenchMessage>(topic, qos);
    // Fills every queue first (and maps and warms the pool).
    const std::size_t filling = (queue_full ? depth : 0) + warmup_messages;
    std::vector<std::int64_t> calls;
    calls.reserve(count);
    for (std::size_t seq = 0; seq < filling + count; ++seq) {
      auto message = pub->borrow_loaned_message();
      message->payload.resize(64);
      message->seq = seq;
      const std::int64_t t0 = now_ns();
      pub->publish(std::move(message));
      const std::int64_t t1 = now_ns();
      if (seq >= filling) calls.push_back(t1 - t0);
      if (!queue_full) {
        auto taken = polling.front()->take_new_data();
        if (!taken || taken->seq != seq)
          throw std::runtime_error("a taken message is not the last");
      }
    }
    // The kernel's word for it: each queue as full as its depth, and
    // everything beyond the depth dropped, or nothing left and nothing dropped.
    const std::optional<agnocast::TopicInfo> info = agnocast::topic_info(topic);
    if (!info || info->subscribers.size() != subscribers) {
      throw std::runtime_error("the topic lost subscribers");
    }
    for (const agnocast::SubscriberInfo& subscriber : info->subscribers) {
      const std::size_t unreceived = queue_full ? depth : 0;
      const std::size_t dropped = queue_full ? filling + count - depth : 0;
      if (subscriber.unreceived != unreceived || subscriber.dropped != dropped) {
        throw std::runtime_error("subscriber " + std::to_string(subscriber.id) + " has " +
                                 std::to_string(subscriber.unreceived) + " unreceived, " +
                                 std::to_string(subscriber.dropped) + " dropped; expected " +
                                 std::to_string(unreceived) + ", " + std::to_string(dropped));
      }
    }
    send_latencies(results.write_fd, calls);
    return 0;
  });
  results.close_write();
  std::vector<std::int64_t> calls = receive_latencies(results.read_fd);
  results.close_read();
  reap(publisher, "publisher");
  if (calls.size() != count) throw std::runtime_error("the publisher missed calls");
  return calls;
}

namespace {

// A reply written before the first request, one per request: what a
// publisher's payload is before publish(), outside the measured window.
template <typename Message, typename Borrow>
std::vector<agnocast::ipc_shared_ptr<Message>> written_replies(std::size_t size, std::size_t count,
                                                               Borrow borrow) {
  std::vector<agnocast::ipc_shared_ptr<Message>> replies;
  for (std::size_t seq = 0; seq < count; ++seq) {
    auto reply = borrow();
    reply->seq = seq;
    reply->payload.resize(size);
    fill_payload(std::span(reply->payload.data(), size), seq);
    replies.push_back(std::move(reply));
  }
  return replies;
}

// The answer to the request of sequence `seq`, whole and in place.
bool reply_intact(const BenchResponse& reply, std::uint64_t seq, std::size_t size) {
  return reply.seq == seq && reply.payload.size() == size &&
         payload_intact(std::span(reply.payload.data(), size), seq);
}

// The asking side of a round trip: before each sample it pauses, writes the
// request and the scratch, then `send(seq, answered)` starts the request
// (after t0) and the executor runs until the answer's callback has called
// answered(t1, reply).  Returns the round trips, warm-up removed.
template <typename Send>
std::vector<std::int64_t> ask_and_time(agnocast::Executor& executor, std::size_t size,
                                       std::size_t total, std::size_t scratch_bytes, Send send) {
  SharedScratch scratch(scratch_bytes);
  std::vector<std::int64_t> round_trips;
  for (std::size_t seq = 0; seq < total; ++seq) {
    settle_between_messages();
    std::int64_t t1 = 0;
    bool answered = false, intact = false;
    auto on_answer = [&](std::int64_t at, const BenchResponse* reply) {
      t1 = at;
      intact = reply && reply_intact(*reply, seq, size);
      answered = true;
    };
    fill_payload(scratch.bytes(), seq);
    const std::int64_t t0 = send(seq, on_answer);
    while (!answered) {
      if (!executor.spin_once(std::chrono::seconds(60))) {
        throw std::runtime_error("a round trip got no answer");
      }
    }
    if (!intact) throw std::runtime_error("a round trip's answer arrived wrong");
    if (seq >= warmup_messages) round_trips.push_back(t1 - t0);
  }
  return round_trips;
}

}  // namespace

std::vector<std::int64_t> run_agnocast_round_trip(std::size_t size, std::size_t count,
                                                  std::size_t scratch_bytes) {
  const std::string name = next_topic("service");
  const std::size_t total = warmup_messages + count;
  Pipe ready = Pipe::open(), stop = Pipe::open(), results = Pipe::open();
  const pid_t server = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_server"};
    std::vector<agnocast::ipc_shared_ptr<BenchResponse>> responses;
    std::size_t answered = 0;
    auto service = node.create_service<BenchService>(
        name, [&](std::shared_ptr<agnocast::Service<BenchService>> serving, agnocast::RequestId id,
                  agnocast::ipc_shared_ptr<const BenchRequest> request) {
          auto response = std::move(responses.at(answered));
          // What it was asked: the client finds a wrong sequence number.
          if (request->seq != answered || request->payload.size() != size) response->seq = ~0ULL;
          ++answered;
          serving->send_response(id, std::move(response));
        });
    responses = written_replies<BenchResponse>(size, total,
                                               [&] { return service->borrow_loaned_response(); });
    // Stopped by the client once it has every answer, not from a callback
    // inside the last sample's window.
    executor.add_fd(stop.read_fd, [&] { executor.cancel(); });
    executor.add_node(node);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    return answered == total ? 0 : 1;
  });
  const pid_t client = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_client"};
    auto caller = node.create_client<BenchService>(name);
    read_bytes(ready.read_fd, 1);
    if (!caller->wait_for_service(std::chrono::seconds(60))) {
      throw std::runtime_error("the benchmark's server did not come");
    }
    executor.add_node(node);
    using Future = agnocast::Client<BenchService>::SharedFuture;
    auto round_trips =
        ask_and_time(executor, size, total, scratch_bytes, [&](std::size_t seq, auto& on_answer) {
          auto request = caller->borrow_loaned_request();
          request->seq = seq;
          request->payload.resize(size);
          fill_payload(std::span(request->payload.data(), size), seq);
          const std::int64_t t0 = now_ns();
          caller->async_send_request(std::move(request), [&on_answer](Future future) {
            const std::int64_t t1 = now_ns();
            try {
              on_answer(t1, future.get().get());
            } catch (const std::exception&) {
              on_answer(t1, nullptr);
            }
          });
          return t0;
        });
    char byte = 1;
    write_all(stop.write_fd, &byte, 1);
    send_latencies(results.write_fd, round_trips);
    return 0;
  });
  results.close_write();
  std::vector<std::int64_t> round_trips = receive_latencies(results.read_fd);
  results.close_read();
  reap(client, "client");
  reap(server, "server");
  if (round_trips.size() != count) throw std::runtime_error("the client missed answers");
  return round_trips;
}

std::vector<std::int64_t> run_agnocast_ping_pong(std::size_t size, std::size_t count) {
  const std::string ping_topic = next_topic("ping"), pong_topic = ping_topic + "_pong";
  const std::size_t total = warmup_messages + count;
  Pipe ready = Pipe::open(), stop = Pipe::open(), results = Pipe::open();
  const pid_t echo = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_echo"};
    auto pong = node.create_publisher<BenchResponse>(pong_topic, agnocast::QoS{1});
    auto pongs =
        written_replies<BenchResponse>(size, total, [&] { return pong->borrow_loaned_message(); });
    std::size_t answered = 0;
    auto ping = node.create_subscription<BenchRequest>(
        ping_topic, agnocast::QoS{10}, [&](const agnocast::ipc_shared_ptr<const BenchRequest>& m) {
          auto reply = std::move(pongs.at(answered));
          if (m->seq != answered || m->payload.size() != size) reply->seq = ~0ULL;
          ++answered;
          pong->publish(std::move(reply));
        });
    executor.add_fd(stop.read_fd, [&] { executor.cancel(); });
    executor.add_node(node);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    return answered == total ? 0 : 1;
  });
  const pid_t asker = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_asker"};
    auto ping = node.create_publisher<BenchRequest>(ping_topic, agnocast::QoS{1});
    std::function<void(std::int64_t, const BenchResponse*)> on_pong;
    auto pong = node.create_subscription<BenchResponse>(
        pong_topic, agnocast::QoS{10}, [&](const agnocast::ipc_shared_ptr<const BenchResponse>& m) {
          const std::int64_t t1 = now_ns();
          on_pong(t1, m.get());
        });
    read_bytes(ready.read_fd, 1);
    executor.add_node(node);
    auto round_trips =
        ask_and_time(executor, size, total, 0, [&](std::size_t seq, auto& on_answer) {
          on_pong = on_answer;
          auto message = ping->borrow_loaned_message();
          message->seq = seq;
          message->payload.resize(size);
          fill_payload(std::span(message->payload.data(), size), seq);
          const std::int64_t t0 = now_ns();
          ping->publish(std::move(message));
          return t0;
        });
    char byte = 1;
    write_all(stop.write_fd, &byte, 1);
    send_latencies(results.write_fd, round_trips);
    return 0;
  });
  results.close_write();
  std::vector<std::int64_t> round_trips = receive_latencies(results.read_fd);
  results.close_read();
  reap(asker, "ping-pong's asker");
  reap(echo, "ping-pong's echo");
  if (round_trips.size() != count) throw std::runtime_error("the ping-pong missed answers");
  return round_trips;
}

std::vector<std::int64_t> run_python_latency(const PythonSubscriber& python, std::size_t size,
                                             std::size_t count, std::size_t scratch_bytes) {
  const std::string topic = next_topic("python");
  const std::size_t total = warmup_messages + count;
  Pipe ack = Pipe::open(), results = Pipe::open();
  pid_t subscriber = spawn([&] {
    ack.close_read();
    results.close_read();
    if (dup2(results.write_fd, STDOUT_FILENO) < 0) return 1;
    setenv("PYTHONPATH", python.package_path.c_str(), 1);
    setenv("PYTHONHASHSEED", "0", 1);  // the same work in every run (icount repeats)
    const std::string count_text = std::to_string(total), size_text = std::to_string(size),
                      ack_text = std::to_string(ack.write_fd);
    execlp(python.interpreter.c_str(), python.interpreter.c_str(), python.script.c_str(),
           topic.c_str(), count_text.c_str(), size_text.c_str(), ack_text.c_str(), nullptr);
    std::cerr << "agnocast-bench: cannot run " << python.interpreter << "\n";
    return 127;
  });
  results.close_write();
  pid_t publisher = spawn([&] {
    results.close_read();
    ack.close_write();  // so that a subscriber gone ends its wait for an ack
    agnocast::Node node{"bench_publisher"};
    auto pub = node.create_publisher<sensor_msgs::msg::PointCloud2>(topic, agnocast::QoS{1});
    // The interpreter starts and imports numpy meanwhile: seconds under emulation.
    if (!pub->wait_for_subscribers(1, std::chrono::seconds(150))) {
      throw std::runtime_error("the Python subscriber did not subscribe");
    }
    SharedScratch scratch(scratch_bytes);
    for (std::size_t seq = 0; seq < total; ++seq) {
      auto message = pub->borrow_loaned_message();
      message->data.resize(size);
      fill_payload(std::span(message->data.data(), size), seq);
      fill_payload(scratch.bytes(), seq);
      message->height = 1;
      message->width = static_cast<std::uint32_t>(size);
      message->point_step = 1;
      message->header.stamp.sec = static_cast<std::int32_t>(seq);
      message->header.stamp.nanosec = message->data[size - 1];  // what the subscriber checks
      pub->publish(std::move(message));
      read_bytes(ack.read_fd, 1);
      settle_between_messages();
    }
    return 0;
  });
  ack.close_write();
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(results.read_fd, buffer, sizeof buffer);
    if (n > 0) {
      text.append(buffer, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  results.close_read();
  ack.close_read();
  reap(publisher, "publisher");
  reap(subscriber, "Python subscriber");
  std::vector<std::int64_t> latencies;
  std::istringstream numbers(text);
  for (std::int64_t latency; numbers >> latency;) {
    if (latency < 0) throw std::runtime_error("python: a message arrived wrong");
    latencies.push_back(latency);
  }
  if (latencies.size() != total) throw std::runtime_error("the Python subscriber missed messages");
  latencies.erase(latencies.begin(), latencies.begin() + warmup_messages);
  return latencies;
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
  return throughput_of(numbers[0], numbers[1], static_cast<std::uint64_t>(numbers[2]), count);
}

namespace {

// What the counters break down: the calls of agnocast's paths and of the
// benchmark's own pacing; "total" has every other call too.
const std::vector<std::string> counted_syscalls{
    "ioctl",        "epoll_wait",      "epoll_pwait", "mq_timedreceive",
    "mq_timedsend", "clock_nanosleep", "read",        "write"};

// One side's window: counters, CPU time and heap allocations read at its
// start and end, and reported as one vector: messages, CPU ns, allocations,
// then (when the kernel has the counters) "total" and the counts in
// counted_syscalls order.
std::optional<SyscallCounter> open_counter() {
  std::string why;
  auto counter = SyscallCounter::open(counted_syscalls, &why);
  if (!counter) std::cerr << "agnocast-bench: system calls not counted: " << why << "\n";
  return counter;
}

struct Window {
  explicit Window(bool count_syscalls) : counter(count_syscalls ? open_counter() : std::nullopt) {}
  std::optional<SyscallCounter> counter;
  SyscallCounts start_counts;
  std::int64_t start_cpu = 0;
  std::uint64_t start_allocations = 0;
  std::vector<std::int64_t> report;

  void begin() {
    start_allocations = allocations_by_this_thread();
    start_cpu = cpu_time_ns();
    if (counter) start_counts = counter->take_reading();
  }
  void end(std::size_t messages) {
    std::optional<SyscallCounts> between;
    if (counter) between = counted_between(start_counts, counter->take_reading());
    const std::int64_t cpu_ns = cpu_time_ns() - start_cpu;
    const auto allocations =
        static_cast<std::int64_t>(allocations_by_this_thread() - start_allocations);
    report = {static_cast<std::int64_t>(messages), cpu_ns, allocations};
    if (!between) return;
    report.push_back(between->at("total"));
    for (const auto& name : counted_syscalls) report.push_back(between->at(name));
  }
};

std::optional<SyscallCounts> counts_per_message(const std::vector<std::int64_t>& report) {
  if (report.size() != 4 + counted_syscalls.size()) return std::nullopt;
  SyscallCounts counts{{"messages", report[0]}, {"total", report[3]}};
  for (std::size_t i = 0; i < counted_syscalls.size(); ++i) {
    counts[counted_syscalls[i]] = report[4 + i];
  }
  return counts;
}

}  // namespace

SteadyResult run_agnocast_steady(std::size_t depth, std::size_t count, std::size_t subscribers,
                                 bool count_syscalls) {
  const std::string topic = next_topic("steady");
  const std::size_t total = steady_warmup_messages + count + 1;
  Pipe ready = Pipe::open(), publisher_report = Pipe::open();
  std::vector<Pipe> reports;
  std::vector<pid_t> subscriber_pids;
  for (std::size_t s = 0; s < subscribers; ++s) {
    reports.push_back(Pipe::open());
    const int report_fd = reports.back().write_fd;
    subscriber_pids.push_back(spawn([&, report_fd] {
      agnocast::SingleThreadedExecutor executor;
      agnocast::Node node{"bench_subscriber"};
      Window window(count_syscalls);
      std::size_t in_window = 0;
      bool counting = false;
      // The callback makes no system call of its own between the two
      // readings: what is counted is the executor's and the library's.  The
      // window goes by sequence numbers, since a QoS 1 subscriber that falls
      // behind loses messages; the newest one always arrives.
      auto subscription = node.create_subscription<BenchMessage>(
          topic, agnocast::QoS{depth}, [&](const agnocast::ipc_shared_ptr<const BenchMessage>& m) {
            if (counting) ++in_window;
            if (!counting && m->seq >= steady_warmup_messages &&
                m->seq < steady_warmup_messages + count) {
              counting = true;
              window.begin();
            } else if (counting && m->seq >= steady_warmup_messages + count) {
              counting = false;
              window.end(in_window);
            }
            if (m->seq + 1 == total) executor.cancel();
          });
      executor.add_node(node);
      char byte = 1;
      write_all(ready.write_fd, &byte, 1);
      executor.spin();
      send_latencies(report_fd, window.report);
      return 0;
    }));
  }
  pid_t publisher = spawn([&] {
    agnocast::Node node{"bench_publisher"};
    auto pub = node.create_publisher<BenchMessage>(topic, agnocast::QoS{depth});
    read_bytes(ready.read_fd, subscribers);
    Window window(count_syscalls);
    std::int64_t next = now_ns();
    for (std::size_t seq = 0; seq < total; ++seq) {
      next += steady_period_ns;
      sleep_until_ns(next);
      if (seq == steady_warmup_messages) window.begin();
      auto message = pub->borrow_loaned_message();
      message->payload.resize(64);
      message->seq = seq;
      message->t0_ns = now_ns();
      pub->publish(std::move(message));
      if (seq + 1 == steady_warmup_messages + count) window.end(count);
    }
    send_latencies(publisher_report.write_fd, window.report);
    return 0;
  });

  publisher_report.close_write();
  std::vector<std::int64_t> publisher_side = receive_latencies(publisher_report.read_fd);
  std::vector<std::vector<std::int64_t>> subscriber_sides;
  for (auto& pipe : reports) {
    pipe.close_write();
    subscriber_sides.push_back(receive_latencies(pipe.read_fd));
    pipe.close_read();
  }
  reap(publisher, "publisher");
  for (pid_t pid : subscriber_pids) reap(pid, "subscriber");
  if (publisher_side.size() < 3 || subscriber_sides.front().size() < 3 ||
      subscriber_sides.front()[0] == 0) {
    throw std::runtime_error("a fixed-rate role measured nothing");
  }
  SteadyResult result;
  result.cpu.publisher_us =
      static_cast<double>(publisher_side[1]) / 1000.0 / static_cast<double>(publisher_side[0]);
  result.cpu.subscriber_us = static_cast<double>(subscriber_sides.front()[1]) / 1000.0 /
                             static_cast<double>(subscriber_sides.front()[0]);
  result.publisher_allocations =
      static_cast<double>(publisher_side[2]) / static_cast<double>(publisher_side[0]);
  result.subscriber_allocations = static_cast<double>(subscriber_sides.front()[2]) /
                                  static_cast<double>(subscriber_sides.front()[0]);
  result.publisher = counts_per_message(publisher_side);
  result.subscriber = counts_per_message(subscriber_sides.front());
  return result;
}

BackgroundTraffic::BackgroundTraffic(std::size_t topics, std::int64_t period_ns) {
  void* memory =
      mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (memory == MAP_FAILED) throw std::runtime_error("mmap failed");
  shared_ = new (memory) Shared{};
  std::vector<std::string> names;
  for (std::size_t t = 0; t < topics; ++t) names.push_back(next_topic("background"));
  Pipe ready = Pipe::open();
  Shared* shared = shared_;
  subscriber_ = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_background_subscriber"};
    std::vector<std::shared_ptr<agnocast::Subscription<BenchMessage>>> subscriptions;
    for (const auto& name : names) {
      subscriptions.push_back(node.create_subscription<BenchMessage>(
          name, agnocast::QoS{10},
          [shared](const agnocast::ipc_shared_ptr<const BenchMessage>&) { ++shared->received; }));
    }
    executor.add_node(node);
    std::thread stopper([&] {
      while (!shared->stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      executor.cancel();
    });
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    stopper.join();
    return 0;
  });
  publisher_ = spawn([&] {
    agnocast::Node node{"bench_background_publisher"};
    std::vector<std::shared_ptr<agnocast::Publisher<BenchMessage>>> publishers;
    for (const auto& name : names) {
      publishers.push_back(node.create_publisher<BenchMessage>(name, agnocast::QoS{10}));
    }
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    // Every topic once a period; a period overrun is not caught up in a burst.
    std::int64_t next = now_ns();
    for (std::uint64_t seq = 0; !shared->stop.load(); ++seq) {
      for (auto& pub : publishers) {
        auto message = pub->borrow_loaned_message();
        message->payload.resize(64);
        message->seq = seq;
        pub->publish(std::move(message));
        ++shared->published;
      }
      next = std::max(next + period_ns, now_ns());
      sleep_until_ns(next);
    }
    return 0;
  });
  read_bytes(ready.read_fd, 2);
  // Let the traffic reach its pace before anything is measured beside it.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  started_ns_ = now_ns();
  received_at_start_ = shared_->received.load();
}

BackgroundTraffic::~BackgroundTraffic() {
  shared_->stop.store(true);
  try {
    reap(publisher_, "background publisher");
    reap(subscriber_, "background subscriber");
  } catch (const std::exception& error) {
    std::cerr << error.what() << "\n";
  }
  munmap(shared_, sizeof(Shared));
}

double BackgroundTraffic::delivered_per_s() const {
  const double seconds = static_cast<double>(now_ns() - started_ns_) / 1e9;
  return static_cast<double>(shared_->received.load() - received_at_start_) / seconds;
}

IdleEndpoints::IdleEndpoints(std::size_t processes, std::size_t topics)
    : IdleEndpoints(processes, topics,
                    [prefix = next_topic("idle")](agnocast::Node& node, std::size_t t) {
                      return node.create_publisher<BenchMessage>(prefix + "_" + std::to_string(t),
                                                                 agnocast::QoS{10});
                    }) {}

IdleEndpoints IdleEndpoints::publishers_of(const std::string& topic, std::size_t publishers) {
  return IdleEndpoints(processes_for(publishers), publishers,
                       [&](agnocast::Node& node, std::size_t) {
                         return node.create_publisher<BenchMessage>(topic, agnocast::QoS{10});
                       });
}

IdleEndpoints IdleEndpoints::polling_subscribers_of(const std::string& topic,
                                                    std::size_t subscribers, std::size_t depth) {
  return IdleEndpoints(
      processes_for(subscribers), subscribers, [&](agnocast::Node& node, std::size_t) {
        return node.create_polling_subscriber<BenchMessage>(topic, agnocast::QoS{depth});
      });
}

IdleEndpoints::IdleEndpoints(std::size_t processes, std::size_t endpoints,
                             const MakeEndpoint& make) {
  Pipe ready = Pipe::open(), release = Pipe::open();
  release_fd_ = release.write_fd;
  std::size_t created = 0;
  for (std::size_t p = 0; p < processes; ++p) {
    // An even share of the endpoints, the first processes one more.
    const std::size_t share = endpoints / processes + (p < endpoints % processes ? 1 : 0);
    const std::size_t first = created;
    created += share;
    processes_.push_back(spawn([&] {
      ::close(release.write_fd);  // the driver's copy alone holds the processes
      agnocast::Node node{"bench_idle_" + std::to_string(p)};
      std::vector<std::shared_ptr<void>> idle;
      idle.reserve(share);
      for (std::size_t t = first; t < first + share; ++t) idle.push_back(make(node, t));
      char byte = 1;
      write_all(ready.write_fd, &byte, 1);
      read_all(release.read_fd, &byte, 1);  // end of file: released
      return 0;
    }));
  }
  release.close_read();
  ready.close_write();
  try {
    read_bytes(ready.read_fd, processes);
  } catch (...) {
    ready.close_read();
    release_all();
    throw;
  }
  ready.close_read();
}

IdleEndpoints::~IdleEndpoints() { release_all(); }

void IdleEndpoints::release_all() noexcept {
  ::close(release_fd_);
  for (pid_t process : processes_) {
    try {
      reap(process, "idle");
    } catch (const std::exception& error) {
      std::cerr << error.what() << "\n";
    }
  }
}

}  // namespace agnocast::bench
