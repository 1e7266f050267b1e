// The kernel's own counters of the whole machine (every CPU), read around one
// measured sample: page faults, TLB flushes, IPIs, context switches and
// migrations.  Where two transports' wall times differ but their
// instructions do not, these say whether the guest kernel did different
// work or the difference lies outside it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bench_support.hpp"

namespace agnocast::bench {

class WindowCounters {
 public:
  // Needs tracefs and the right to count every CPU (root in the test VM);
  // empty, with the reason in *why, otherwise.
  static std::optional<WindowCounters> open(std::string* why);
  ~WindowCounters();
  WindowCounters(WindowCounters&& other) noexcept;
  WindowCounters(const WindowCounters&) = delete;
  WindowCounters& operator=(const WindowCounters&) = delete;
  WindowCounters& operator=(WindowCounters&& other) noexcept;

  // The counters' names, in the order of a reading.
  const std::vector<std::string>& names() const { return names_; }
  // Every counter summed over the CPUs.
  std::vector<std::int64_t> read() const;

 private:
  WindowCounters() = default;
  std::vector<std::string> names_;
  std::vector<std::vector<int>> fds_;  // per counter, one per CPU
};

// What each counter did between two readings.
std::vector<std::int64_t> counters_between(const std::vector<std::int64_t>& before,
                                           const std::vector<std::int64_t>& after);

// A sender's record of its samples' windows: the counters read right before
// the clock starts and again once the receiver has acked, how long the send
// call took and how much of that the sending thread itself ran (its CPU time:
// on one CPU, receivers woken inside the call run inside it too), one line
// per sample ("window WHO seq=N send_ns=... send_cpu_ns=... name=value ..."),
// appended to the file AGNOCAST_BENCH_WINDOWS_FILE names (or stderr): the
// times when AGNOCAST_BENCH_WINDOWS is set, the counters too when it is
// "counters".
class SampleWindows {
 public:
  explicit SampleWindows(std::string who);
  // Inline tests, so that untimed runs (icount's) spend next to no
  // instructions in the measured window.
  void before_send() {
    if (timed_) start();
  }
  void sent() {
    if (timed_) {
      send_ns_ = now_ns() - start_ns_;
      send_cpu_ns_ = thread_cpu_ns() - start_cpu_ns_;
    }
  }
  void after_ack(std::uint64_t seq) {
    if (timed_) record(seq);
  }

 private:
  void start();
  void record(std::uint64_t seq);
  static std::int64_t thread_cpu_ns();
  std::string who_;
  bool timed_ = false;
  std::optional<WindowCounters> counters_;
  std::vector<std::int64_t> before_;
  std::int64_t start_ns_ = 0, send_ns_ = 0, start_cpu_ns_ = 0, send_cpu_ns_ = 0;
  int cpu_ = -1;
};

}  // namespace agnocast::bench
