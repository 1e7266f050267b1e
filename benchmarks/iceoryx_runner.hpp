// Runs the iceoryx latency roles (a separate program, since iceoryx is a
// separate runtime) under a RouDi started for the purpose, with memory pools
// that reach 64 MiB (RouDi's built-in ones stop at 4 MiB).
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "bench_support.hpp"

namespace agnocast::bench {

class IceoryxRunner {
 public:
  // Empty when iox-roudi or the role program is missing.
  static std::optional<IceoryxRunner> start(const std::string& role_program);
  ~IceoryxRunner();
  IceoryxRunner(IceoryxRunner&& other) noexcept;
  IceoryxRunner(const IceoryxRunner&) = delete;
  IceoryxRunner& operator=(const IceoryxRunner&) = delete;
  IceoryxRunner& operator=(IceoryxRunner&&) = delete;

  // One-way latencies (ns) of `count` messages of `size` bytes, the
  // publisher writing `scratch_bytes` of shared memory before each.
  std::vector<std::int64_t> measure(std::size_t size, std::size_t count, std::size_t scratch_bytes);

  // `count` messages of `size` bytes back to back to one subscriber, as
  // run_agnocast_throughput.
  Throughput throughput(std::size_t size, std::size_t count);

  // CPU time of each side per 64 B message, one message a millisecond.
  CpuPerMessage cpu_per_message(std::size_t count);

 private:
  IceoryxRunner(std::string role_program, int roudi_pid)
      : role_program_(std::move(role_program)), roudi_pid_(roudi_pid) {}
  std::string role_program_;
  int roudi_pid_ = -1;
  unsigned pairs_ = 0;  // role pairs this process started: with its pid, a unique instance
};

}  // namespace agnocast::bench
