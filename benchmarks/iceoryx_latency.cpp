// Eclipse iceoryx (Debian's 2.0) measured exactly like agnocast: the payload
// is written into a loaned chunk, the clock starts right before publish, and
// the subscriber, asleep in a WaitSet (no busy polling), stops it on taking
// the chunk.  Run by agnocast-bench with RouDi already up.  With --steady,
// one message a millisecond and no acks: each side reports its CPU time.
// With --throughput, messages back to back and no acks: the subscriber
// reports how many it received between the first one's send and the last.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <span>
#include <thread>
#include <vector>

#include "bench_support.hpp"
#include "iceoryx_hoofs/log/logmanager.hpp"
#include "iceoryx_posh/popo/untyped_publisher.hpp"
#include "iceoryx_posh/popo/untyped_subscriber.hpp"
#include "iceoryx_posh/popo/wait_set.hpp"
#include "iceoryx_posh/runtime/posh_runtime.hpp"
#include "window_counters.hpp"

namespace bench = agnocast::bench;

namespace {

struct Header {
  std::uint64_t seq;
  std::int64_t t0_ns;
};

// Each measurement has its own service instance and runtime names, so
// nothing RouDi still holds of an earlier pair's processes meets this pair.
iox::capro::ServiceDescription service_of(const std::string& instance) {
  return {"agnocast_bench", iox::capro::IdString_t(iox::cxx::TruncateToCapacity, instance),
          "chunk"};
}

iox::RuntimeName_t runtime_name(const char* role, const std::string& instance) {
  return iox::RuntimeName_t(iox::cxx::TruncateToCapacity,
                            std::string("agnocast_bench_") + role + "_" + instance);
}

struct Options {
  std::size_t size = 64;
  std::size_t count = 100;
  std::size_t scratch_bytes = 0;
  bool steady = false;
  bool throughput = false;
  std::string instance = "0";
  int ready_fd = -1, ack_fd = -1, results_fd = -1;
};

void report_cpu(int results_fd, std::int64_t side, std::int64_t cpu_ns) {
  const std::int64_t report[2] = {side, cpu_ns};
  bench::write_all(results_fd, report, sizeof report);
}

// Back to back, as agnocast's throughput publisher: each chunk's payload
// written (zeros, as agnocast's vector resize writes them), its header
// stamped. A loan refused (every chunk still queued or held) is retried.
int publish_back_to_back(iox::popo::UntypedPublisher& publisher, const Options& options) {
  for (std::size_t seq = 0; seq < options.count; ++seq) {
    auto loan =
        publisher.loan(static_cast<std::uint32_t>(sizeof(Header) + options.size), alignof(Header));
    while (loan.has_error()) {
      std::this_thread::yield();
      loan = publisher.loan(static_cast<std::uint32_t>(sizeof(Header) + options.size),
                            alignof(Header));
    }
    auto* chunk = static_cast<std::uint8_t*>(loan.value());
    std::memset(chunk + sizeof(Header), 0, options.size);
    auto* header = reinterpret_cast<Header*>(chunk);
    header->seq = seq;
    header->t0_ns = bench::now_ns();
    publisher.publish(chunk);
  }
  return 0;
}

int run_publisher(const Options& options) {
  iox::runtime::PoshRuntime::initRuntime(runtime_name("pub", options.instance));
  iox::popo::UntypedPublisher publisher(service_of(options.instance));
  char byte = 0;
  if (!bench::read_all(options.ready_fd, &byte, 1)) return 1;
  while (!publisher.hasSubscribers()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (options.throughput) return publish_back_to_back(publisher, options);
  bench::SharedScratch scratch(options.scratch_bytes);
  bench::SampleWindows windows("iceoryx size=" + std::to_string(options.size) +
                               " scratch=" + std::to_string(options.scratch_bytes));
  const std::size_t total =
      options.steady ? bench::steady_warmup_messages + options.count : options.count;
  std::int64_t next = bench::now_ns(), cpu0 = 0;
  for (std::size_t seq = 0; seq < total; ++seq) {
    if (options.steady) {
      next += bench::steady_period_ns;
      bench::sleep_until_ns(next);
    }
    auto loan =
        publisher.loan(static_cast<std::uint32_t>(sizeof(Header) + options.size), alignof(Header));
    if (loan.has_error()) {
      std::cerr << "iceoryx: loan of " << options.size << " bytes failed\n";
      return 1;
    }
    auto* chunk = static_cast<std::uint8_t*>(loan.value());
    bench::fill_payload(std::span(chunk + sizeof(Header), options.size), seq);
    bench::fill_payload(scratch.bytes(), seq);
    auto* header = reinterpret_cast<Header*>(chunk);
    header->seq = seq;
    windows.before_send();
    header->t0_ns = bench::now_ns();
    publisher.publish(chunk);
    windows.sent();
    if (options.steady) {
      if (seq + 1 == bench::steady_warmup_messages) cpu0 = bench::cpu_time_ns();
      continue;
    }
    if (!bench::read_all(options.ack_fd, &byte, 1)) return 1;
    windows.after_ack(seq);
    bench::settle_between_messages();
  }
  if (options.steady) report_cpu(options.results_fd, 0, bench::cpu_time_ns() - cpu0);
  return 0;
}

// Takes until the last message (the newest is never discarded), then
// reports {first one's send time, last one's arrival, messages received}.
int receive_back_to_back(iox::popo::UntypedSubscriber& subscriber, iox::popo::WaitSet<>& waitset,
                         const Options& options) {
  std::int64_t first_t0 = 0, last_t1 = 0, received = 0;
  bool done = false;
  while (!done) {
    waitset.wait();
    while (!done) {
      auto taken = subscriber.take();
      if (taken.has_error()) break;
      Header header;
      std::memcpy(&header, taken.value(), sizeof header);
      if (received++ == 0) first_t0 = header.t0_ns;
      subscriber.release(taken.value());
      if (header.seq + 1 == options.count) {
        last_t1 = bench::now_ns();
        done = true;
      }
    }
  }
  const std::int64_t report[3] = {first_t0, last_t1, received};
  bench::write_all(options.results_fd, report, sizeof report);
  return 0;
}

int run_subscriber(const Options& options) {
  iox::runtime::PoshRuntime::initRuntime(runtime_name("sub", options.instance));
  iox::popo::SubscriberOptions subscriber_options;
  // Back to back, as deep a queue as iceoryx allows (agnocast's subscriber
  // keeps 1,000).
  subscriber_options.queueCapacity = options.throughput ? 256 : 16;
  iox::popo::UntypedSubscriber subscriber(service_of(options.instance), subscriber_options);
  iox::popo::WaitSet<> waitset;
  if (waitset.attachState(subscriber, iox::popo::SubscriberState::HAS_DATA).has_error()) return 1;
  char byte = 1;
  bench::write_all(options.ready_fd, &byte, 1);

  const std::size_t total =
      options.steady ? bench::steady_warmup_messages + options.count : options.count;
  if (options.throughput) return receive_back_to_back(subscriber, waitset, options);
  std::vector<std::int64_t> latencies;
  latencies.reserve(total);
  // In a fixed-rate run the subscription may complete after the first
  // messages were sent: CPU is counted from the first message after the
  // warm-up that arrives, over the messages that arrive after it.
  std::int64_t cpu0 = 0;
  std::size_t counted = 0;
  bool counting = false, done = false;
  while (!done) {
    waitset.wait();
    while (!done) {
      auto taken = subscriber.take();
      if (taken.has_error()) break;
      std::int64_t t1 = bench::now_ns();
      auto* chunk = static_cast<const std::uint8_t*>(taken.value());
      Header header;
      std::memcpy(&header, chunk, sizeof header);
      if (options.steady) {
        subscriber.release(taken.value());
        if (counting) ++counted;
        if (!counting && header.seq + 1 >= bench::steady_warmup_messages) {
          counting = true;
          cpu0 = bench::cpu_time_ns();
        }
        done = header.seq + 1 == total;
        continue;
      }
      bool intact =
          bench::payload_intact(std::span(chunk + sizeof(Header), options.size), header.seq);
      latencies.push_back(intact ? t1 - header.t0_ns : -1);
      subscriber.release(taken.value());
      bench::write_all(options.ack_fd, &byte, 1);
      done = latencies.size() == total;
    }
  }
  if (options.steady) {
    if (counted == 0) return 1;
    // Scaled to the publisher's count, so the runner divides both alike.
    const double per_message = static_cast<double>(bench::cpu_time_ns() - cpu0) / counted;
    report_cpu(options.results_fd, 1,
               static_cast<std::int64_t>(per_message * static_cast<double>(options.count)));
  } else {
    bench::send_latencies(options.results_fd, latencies);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"iceoryx latency role for agnocast-bench"};
  std::string role;
  std::string size_text = "64";
  Options options;
  app.add_option("role", role)->required()->check(CLI::IsMember({"pub", "sub"}));
  app.add_option("--size", size_text);
  app.add_option("--count", options.count);
  app.add_option("--scratch", options.scratch_bytes, "bytes written elsewhere before each message");
  app.add_option("--instance", options.instance, "service instance and runtime name suffix");
  app.add_flag("--steady", options.steady, "one message a millisecond; report CPU time");
  app.add_flag("--throughput", options.throughput, "back to back; report messages received");
  app.add_option("--ready-fd", options.ready_fd)->required();
  app.add_option("--ack-fd", options.ack_fd)->required();
  app.add_option("--results-fd", options.results_fd);
  CLI11_PARSE(app, argc, argv);
  // Quietly: the level's own announcement would fill the benchmark's log.
  iox::log::LogManager::GetLogManager().SetDefaultLogLevel(iox::log::LogLevel::kWarn,
                                                           iox::log::LogLevelOutput::kHideLogLevel);
  options.size = bench::parse_size(size_text);
  if (role == "pub") return run_publisher(options);
  return run_subscriber(options);
}
