// agnocast's side of the benchmark: publisher and subscriber processes forked
// from the driver, which itself never touches agnocast.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "syscall_counter.hpp"

namespace agnocast {
class Node;
}

namespace agnocast::bench {

// How a one-way latency run differs from the plain one.
struct LatencyOptions {
  // Bytes of private memory the publisher writes before each message: a
  // control for what writing a large payload does to the caches, apart from
  // the payload's size itself.
  std::size_t scratch_bytes = 0;
  // Both sides' QoS depth; by default the publisher keeps 1 message and each
  // subscriber 10.
  std::optional<std::size_t> depth{};
  // The topic; by default one of its own.
  std::string topic{};
};
// One-way latency of `count` messages of `size` payload bytes to each of
// `subscribers` callback subscribers, one message in flight at a time; the
// result holds one latency vector per subscriber (warm-up messages removed).
std::vector<std::vector<std::int64_t>> run_agnocast_latency(std::size_t size, std::size_t count,
                                                            std::size_t subscribers,
                                                            const LatencyOptions& options = {});

// The publisher's publish() call (wall time, one 64 B message each) on a
// topic whose `subscribers` polling subscribers, like the publisher, have
// QoS depth `depth`.  With `queue_full` no subscriber ever takes: each holds
// `depth` unreceived entries, so every publish drops each one's oldest (and
// the publisher reclaims what no one holds); the kernel's counters are checked
// to say so afterwards.  Without, the one subscriber (`subscribers` must be 1)
// takes each message before the next.  The subscribers share the publisher's
// process, up to 1,000 of them (the module's default endpoints per process is
// 1,024); the rest live in processes of their own.
std::vector<std::int64_t> run_agnocast_publish_call(std::size_t depth, std::size_t subscribers,
                                                    std::size_t count, bool queue_full);

// Request to response: `count` round trips of a service whose request and
// response each carry `size` payload bytes, from async_send_request() (the
// request written) to the first line of the client's response callback, one
// request in flight, both sides asleep before each.  The server answers from
// its callback with a response it wrote before the first request came; the
// client writes scratch_bytes of shared memory before each request (as
// run_agnocast_latency), so that every size can write as many bytes.
std::vector<std::int64_t> run_agnocast_round_trip(std::size_t size, std::size_t count,
                                                  std::size_t scratch_bytes);

// The same window over two one-way publishes of `size` payload bytes: a
// ping on one topic, whose callback publishes a pong written beforehand on a
// second topic, to the first line of the pong's callback.
std::vector<std::int64_t> run_agnocast_ping_pong(std::size_t size, std::size_t count);

// How to start the Python subscriber (python_subscriber.py): the interpreter,
// the script and the folder holding the agnocast package (PYTHONPATH).
struct PythonSubscriber {
  std::string interpreter;
  std::string script;
  std::string package_path;
};
// One-way latency of `count` sensor_msgs/PointCloud2 messages of `size` data
// bytes from a C++ publisher to the callback of a Python subscription, one
// message in flight, warm-up messages removed; as run_agnocast_latency, the
// publisher writes scratch_bytes of private memory before each message.
std::vector<std::int64_t> run_python_latency(const PythonSubscriber& python, std::size_t size,
                                             std::size_t count, std::size_t scratch_bytes);

// `count` messages of `size` payload bytes published back to back (each
// one's payload written) to one subscriber that keeps 1,000; those it had no
// room for are dropped, the newest never.
Throughput run_agnocast_throughput(std::size_t size, std::size_t count);

// One message a millisecond from one publisher to `subscribers`, both sides
// with QoS depth `depth`: CPU time and heap allocations of each side over
// `count` messages (the first subscriber's), in steady state, and with
// `count_syscalls` the system calls too.  The counters cost each counted
// call thousands of instructions, so CPU time is only fair (comparable with
// iceoryx's and the floor's, taken without counters) from a run without
// them.  The counts are over "messages" messages (a QoS 1 subscriber may
// lose some).
struct SteadyResult {
  CpuPerMessage cpu;
  std::optional<SyscallCounts> publisher;  // empty when not counted or no counters
  std::optional<SyscallCounts> subscriber;
  // Heap allocations (operator new) per message on each side's thread.
  double publisher_allocations = 0;
  double subscriber_allocations = 0;
};
SteadyResult run_agnocast_steady(std::size_t depth, std::size_t count, std::size_t subscribers,
                                 bool count_syscalls);

// `topics` other topics, each carrying one 64 B message every `period_ns`
// from one publisher process to one subscriber process, while it lives.
class BackgroundTraffic {
 public:
  BackgroundTraffic(std::size_t topics, std::int64_t period_ns);
  ~BackgroundTraffic();
  BackgroundTraffic(const BackgroundTraffic&) = delete;
  BackgroundTraffic& operator=(const BackgroundTraffic&) = delete;
  // Messages delivered per second, all topics together, since it started.
  double delivered_per_s() const;

 private:
  struct Shared {
    std::atomic<bool> stop{false};
    std::atomic<std::uint64_t> published{0};
    std::atomic<std::uint64_t> received{0};
  };
  Shared* shared_ = nullptr;
  pid_t publisher_ = -1;
  pid_t subscriber_ = -1;
  std::int64_t started_ns_ = 0;
  std::uint64_t received_at_start_ = 0;
};

// What a large system has registered beside the measured topic, while it
// lives: `processes` processes attached to agnocast, holding `topics` idle
// topics between them (one publisher each, nothing ever published).
class IdleEndpoints {
 public:
  IdleEndpoints(std::size_t processes, std::size_t topics);
  // `publishers` idle publishers of the one topic `topic`, in as few
  // processes as the endpoint limit per process allows.
  static IdleEndpoints publishers_of(const std::string& topic, std::size_t publishers);
  // `subscribers` polling subscribers of `topic` with QoS `depth`, which
  // never take: likewise.
  static IdleEndpoints polling_subscribers_of(const std::string& topic, std::size_t subscribers,
                                              std::size_t depth);
  ~IdleEndpoints();
  IdleEndpoints(const IdleEndpoints&) = delete;
  IdleEndpoints& operator=(const IdleEndpoints&) = delete;

 private:
  // Endpoint t (of `endpoints`), made by a node of its process.
  using MakeEndpoint = std::function<std::shared_ptr<void>(agnocast::Node& node, std::size_t t)>;
  IdleEndpoints(std::size_t processes, std::size_t endpoints, const MakeEndpoint& make);
  // The module's default endpoints per process is 1,024: 1,000 a process.
  static std::size_t processes_for(std::size_t endpoints) { return (endpoints + 999) / 1000; }
  void release_all() noexcept;

  int release_fd_ = -1;  // closing it lets every process go
  std::vector<pid_t> processes_;
};

}  // namespace agnocast::bench
