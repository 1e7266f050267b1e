#include "window_counters.hpp"

#include <fcntl.h>
#include <linux/perf_event.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "bench_support.hpp"
#include "tracepoint_counter.hpp"

namespace agnocast::bench {
namespace {

struct Event {
  const char* name;
  const char* tracepoint;
  const char* filter;  // nullptr: every hit
};

// tlb:tlb_flush's reason 0 is the flush of a context switch; the others are
// shootdowns (sent, received or local) of a changed mapping.
const Event events[] = {
    {"page_faults_user", "exceptions/page_fault_user", nullptr},
    {"page_faults_kernel", "exceptions/page_fault_kernel", nullptr},
    {"tlb_flush_switch", "tlb/tlb_flush", "reason == 0"},
    {"tlb_flush_shootdown", "tlb/tlb_flush", "reason != 0"},
    {"call_function_ipis", "irq_vectors/call_function_entry", nullptr},
    {"call_function_single_ipis", "irq_vectors/call_function_single_entry", nullptr},
    {"reschedule_ipis", "irq_vectors/reschedule_entry", nullptr},
    {"context_switches", "sched/sched_switch", nullptr},
    {"migrations", "sched/sched_migrate_task", nullptr},
    {"mmap_calls", "syscalls/sys_enter_mmap", nullptr},
    {"munmap_calls", "syscalls/sys_enter_munmap", nullptr},
    {"madvise_calls", "syscalls/sys_enter_madvise", nullptr},
    {"lock_contentions", "lock/contention_begin", nullptr},
};

}  // namespace

std::optional<WindowCounters> WindowCounters::open(std::string* why) {
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  WindowCounters counters;
  for (const Event& event : events) {
    const auto id = tracepoint_id(event.tracepoint);
    if (!id) continue;  // a kernel without it: the others still count
    counters.names_.emplace_back(event.name);
    std::vector<int>& fds = counters.fds_.emplace_back();
    for (int cpu = 0; cpu < cpus; ++cpu) {
      const int fd = open_tracepoint_counter(*id, -1, cpu, -1, PERF_FLAG_FD_CLOEXEC, false);
      if (fd >= 0) fds.push_back(fd);
      if (fd >= 0 && event.filter && ioctl(fd, PERF_EVENT_IOC_SET_FILTER, event.filter) != 0) {
        *why = std::string("filter on ") + event.tracepoint + ": " + std::strerror(errno);
        return std::nullopt;
      }
      if (fd < 0) {
        *why = std::string("counting ") + event.tracepoint + ": " + std::strerror(errno);
        return std::nullopt;
      }
    }
  }
  if (counters.names_.empty()) {
    *why = "no tracepoint of the counted events in tracefs";
    return std::nullopt;
  }
  return counters;
}

WindowCounters::~WindowCounters() {
  for (const auto& fds : fds_) {
    for (int fd : fds) ::close(fd);
  }
}

WindowCounters::WindowCounters(WindowCounters&& other) noexcept
    : names_(std::move(other.names_)), fds_(std::move(other.fds_)) {}

WindowCounters& WindowCounters::operator=(WindowCounters&& other) noexcept {
  std::swap(names_, other.names_);
  std::swap(fds_, other.fds_);  // the other closes what this held
  return *this;
}

std::vector<std::int64_t> WindowCounters::read() const {
  std::vector<std::int64_t> values;
  for (const auto& fds : fds_) {
    std::int64_t sum = 0;
    for (int fd : fds) {
      std::uint64_t value = 0;
      if (::read(fd, &value, sizeof value) == sizeof value) sum += static_cast<std::int64_t>(value);
    }
    values.push_back(sum);
  }
  return values;
}

std::vector<std::int64_t> counters_between(const std::vector<std::int64_t>& before,
                                           const std::vector<std::int64_t>& after) {
  std::vector<std::int64_t> delta(after.size());
  for (std::size_t i = 0; i < after.size() && i < before.size(); ++i)
    delta[i] = after[i] - before[i];
  return delta;
}

SampleWindows::SampleWindows(std::string who) : who_(std::move(who)) {
  const char* mode = std::getenv("AGNOCAST_BENCH_WINDOWS");
  if (!mode) return;
  timed_ = true;
  if (std::string(mode) != "counters") return;
  std::string why;
  counters_ = WindowCounters::open(&why);
  if (!counters_) std::fprintf(stderr, "agnocast-bench: no window counters: %s\n", why.c_str());
}

std::int64_t SampleWindows::thread_cpu_ns() {
  timespec now{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void SampleWindows::start() {
  if (counters_) before_ = counters_->read();
  cpu_ = sched_getcpu();
  start_cpu_ns_ = thread_cpu_ns();
  start_ns_ = now_ns();
}

void SampleWindows::record(std::uint64_t seq) {
  const std::int64_t acked_ns = now_ns() - start_ns_;
  const std::vector<std::int64_t> delta =
      counters_ ? counters_between(before_, counters_->read()) : std::vector<std::int64_t>{};
  std::string line = "window " + who_ + " seq=" + std::to_string(seq) +
                     " cpu=" + std::to_string(cpu_) + " send_ns=" + std::to_string(send_ns_) +
                     " send_cpu_ns=" + std::to_string(send_cpu_ns_) +
                     " acked_ns=" + std::to_string(acked_ns);
  for (std::size_t i = 0; i < delta.size(); ++i) {
    line += " " + counters_->names()[i] + "=" + std::to_string(delta[i]);
  }
  // One write per line, so lines of processes appending to one file stay whole.
  line += "\n";
  const char* path = std::getenv("AGNOCAST_BENCH_WINDOWS_FILE");
  const int fd = path ? ::open(path, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600) : 2;
  if (fd < 0) return;
  [[maybe_unused]] const ssize_t written = ::write(fd, line.data(), line.size());
  if (fd != 2) ::close(fd);
}

}  // namespace agnocast::bench
