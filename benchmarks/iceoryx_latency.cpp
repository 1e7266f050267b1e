// Eclipse iceoryx (Debian's 2.0) measured exactly like agnocast: the payload
// is written into a loaned chunk, the clock starts right before publish, and
// the subscriber, asleep in a WaitSet (no busy polling), stops it on taking
// the chunk.  Run by agnocast-bench with RouDi already up.
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

namespace bench = agnocast::bench;

namespace {

struct Header {
  std::uint64_t seq;
  std::int64_t t0_ns;
};

const iox::capro::ServiceDescription service{"agnocast_bench", "latency", "chunk"};

int run_publisher(std::size_t size, std::size_t count, int ready_fd, int ack_fd) {
  iox::runtime::PoshRuntime::initRuntime("agnocast_bench_pub");
  iox::popo::UntypedPublisher publisher(service);
  char byte = 0;
  if (!bench::read_all(ready_fd, &byte, 1)) return 1;
  while (!publisher.hasSubscribers()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  for (std::size_t seq = 0; seq < count; ++seq) {
    auto loan = publisher.loan(static_cast<std::uint32_t>(sizeof(Header) + size), alignof(Header));
    if (loan.has_error()) {
      std::cerr << "iceoryx: loan of " << size << " bytes failed\n";
      return 1;
    }
    auto* chunk = static_cast<std::uint8_t*>(loan.value());
    bench::fill_payload(std::span(chunk + sizeof(Header), size), seq);
    auto* header = reinterpret_cast<Header*>(chunk);
    header->seq = seq;
    header->t0_ns = bench::now_ns();
    publisher.publish(chunk);
    if (!bench::read_all(ack_fd, &byte, 1)) return 1;
    bench::settle_between_messages();
  }
  return 0;
}

int run_subscriber(std::size_t size, std::size_t count, int ready_fd, int ack_fd, int results_fd) {
  iox::runtime::PoshRuntime::initRuntime("agnocast_bench_sub");
  iox::popo::SubscriberOptions options;
  options.queueCapacity = 16;
  iox::popo::UntypedSubscriber subscriber(service, options);
  iox::popo::WaitSet<> waitset;
  if (waitset.attachState(subscriber, iox::popo::SubscriberState::HAS_DATA).has_error()) return 1;
  char byte = 1;
  bench::write_all(ready_fd, &byte, 1);

  std::vector<std::int64_t> latencies;
  latencies.reserve(count);
  while (latencies.size() < count) {
    waitset.wait();
    while (latencies.size() < count) {
      auto taken = subscriber.take();
      if (taken.has_error()) break;
      std::int64_t t1 = bench::now_ns();
      auto* chunk = static_cast<const std::uint8_t*>(taken.value());
      Header header;
      std::memcpy(&header, chunk, sizeof header);
      bool intact = bench::payload_intact(std::span(chunk + sizeof(Header), size), header.seq);
      latencies.push_back(intact ? t1 - header.t0_ns : -1);
      subscriber.release(taken.value());
      bench::write_all(ack_fd, &byte, 1);
    }
  }
  bench::send_latencies(results_fd, latencies);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"iceoryx latency role for agnocast-bench"};
  std::string role;
  std::string size_text = "64";
  std::size_t count = 100;
  int ready_fd = -1, ack_fd = -1, results_fd = -1;
  app.add_option("role", role)->required()->check(CLI::IsMember({"pub", "sub"}));
  app.add_option("--size", size_text);
  app.add_option("--count", count);
  app.add_option("--ready-fd", ready_fd)->required();
  app.add_option("--ack-fd", ack_fd)->required();
  app.add_option("--results-fd", results_fd);
  CLI11_PARSE(app, argc, argv);
  iox::log::LogManager::GetLogManager().SetDefaultLogLevel(iox::log::LogLevel::kWarn);
  std::size_t size = bench::parse_size(size_text);
  if (role == "pub") return run_publisher(size, count, ready_fd, ack_fd);
  return run_subscriber(size, count, ready_fd, ack_fd, results_fd);
}
