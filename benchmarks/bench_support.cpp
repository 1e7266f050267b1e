#include "bench_support.hpp"

#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace agnocast::bench {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void settle_between_messages() {
  timespec pause{0, 500'000};
  while (nanosleep(&pause, &pause) != 0 && errno == EINTR) {
  }
}

void sleep_until_ns(std::int64_t deadline_ns) {
  timespec at{static_cast<time_t>(deadline_ns / 1'000'000'000), deadline_ns % 1'000'000'000};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
  }
}

std::int64_t cpu_time_ns() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto ns = [](const timeval& tv) {
    return static_cast<std::int64_t>(tv.tv_sec) * 1'000'000'000 + tv.tv_usec * 1000;
  };
  return ns(usage.ru_utime) + ns(usage.ru_stime);
}

CpuPerMessage per_message(std::int64_t publisher_ns, std::int64_t subscriber_ns,
                          std::size_t messages) {
  const double n = static_cast<double>(messages);
  return {static_cast<double>(publisher_ns) / 1000.0 / n,
          static_cast<double>(subscriber_ns) / 1000.0 / n};
}

SharedScratch::SharedScratch(std::size_t bytes) : size_(bytes) {
  if (bytes == 0) return;
  int fd = memfd_create("agnocast_bench_scratch", MFD_CLOEXEC);
  if (fd < 0 || ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
    throw std::system_error(errno, std::generic_category(), "scratch memfd");
  }
  void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (memory == MAP_FAILED) throw std::system_error(errno, std::generic_category(), "scratch");
  data_ = static_cast<std::uint8_t*>(memory);
}

SharedScratch::~SharedScratch() {
  if (data_) munmap(data_, size_);
}

namespace {
// One pattern word per 8 bytes: under TCG a word store costs about what a
// byte store does, so the 64 MiB every sample writes stays affordable.
std::uint64_t pattern_word(std::uint64_t seq, std::size_t word) {
  return (seq * 0x9e3779b97f4a7c15ULL) ^ (word * 0xbf58476d1ce4e5b9ULL) ^ (word >> 9);
}
}  // namespace

void fill_payload(std::span<std::uint8_t> payload, std::uint64_t seq) {
  const std::size_t words = payload.size() / sizeof(std::uint64_t);
  for (std::size_t i = 0; i < words; ++i) {
    const std::uint64_t value = pattern_word(seq, i);
    std::memcpy(payload.data() + i * sizeof value, &value, sizeof value);
  }
  const std::size_t tail_bytes = payload.size() % sizeof(std::uint64_t);
  if (tail_bytes == 0) return;  // an empty payload's data() may be null, even for no bytes
  const std::uint64_t tail = pattern_word(seq, words);
  std::memcpy(payload.data() + words * sizeof tail, &tail, tail_bytes);
}

bool payload_intact(std::span<const std::uint8_t> payload, std::uint64_t seq) {
  const std::size_t words = payload.size() / sizeof(std::uint64_t);
  for (std::size_t i = 0; i < words; ++i) {
    const std::uint64_t expected = pattern_word(seq, i);
    if (std::memcmp(payload.data() + i * sizeof expected, &expected, sizeof expected) != 0) {
      return false;
    }
  }
  const std::size_t tail_bytes = payload.size() % sizeof(std::uint64_t);
  if (tail_bytes == 0) return true;
  const std::uint64_t tail = pattern_word(seq, words);
  return std::memcmp(payload.data() + words * sizeof tail, &tail, tail_bytes) == 0;
}

LatencyStats summarize(std::vector<std::int64_t> latencies_ns) {
  LatencyStats stats;
  stats.samples = latencies_ns.size();
  if (latencies_ns.empty()) return stats;
  std::sort(latencies_ns.begin(), latencies_ns.end());
  auto percentile = [&](double p) {
    auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(latencies_ns.size())));
    rank = std::clamp<std::size_t>(rank, 1, latencies_ns.size());
    return static_cast<double>(latencies_ns[rank - 1]) / 1000.0;
  };
  stats.p50_us = percentile(0.50);
  stats.p99_us = percentile(0.99);
  return stats;
}

Pipe Pipe::open() {
  int fds[2];
  if (pipe(fds) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  return Pipe{fds[0], fds[1]};
}

void Pipe::close_read() {
  if (read_fd >= 0) ::close(read_fd);
  read_fd = -1;
}

void Pipe::close_write() {
  if (write_fd >= 0) ::close(write_fd);
  write_fd = -1;
}

void write_all(int fd, const void* data, std::size_t size) {
  auto* bytes = static_cast<const char*>(data);
  while (size > 0) {
    ssize_t n = ::write(fd, bytes, size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::system_error(errno, std::generic_category(), "write");
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
}

bool read_all(int fd, void* data, std::size_t size) {
  auto* bytes = static_cast<char*>(data);
  while (size > 0) {
    ssize_t n = ::read(fd, bytes, size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::system_error(errno, std::generic_category(), "read");
    if (n == 0) return false;
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

void send_latencies(int fd, const std::vector<std::int64_t>& latencies_ns) {
  std::uint64_t count = latencies_ns.size();
  write_all(fd, &count, sizeof count);
  write_all(fd, latencies_ns.data(), count * sizeof(std::int64_t));
}

std::vector<std::int64_t> receive_latencies(int fd) {
  std::uint64_t count = 0;
  if (!read_all(fd, &count, sizeof count)) return {};
  std::vector<std::int64_t> latencies(count);
  if (!read_all(fd, latencies.data(), count * sizeof(std::int64_t))) return {};
  return latencies;
}

std::size_t parse_size(const std::string& text) {
  std::size_t digits = 0;
  std::size_t value = std::stoull(text, &digits);
  std::string unit = text.substr(digits);
  if (unit.empty()) return value;
  if (unit == "K" || unit == "KiB") return value << 10;
  if (unit == "M" || unit == "MiB") return value << 20;
  if (unit == "G" || unit == "GiB") return value << 30;
  throw std::invalid_argument("size '" + text + "': use a number with an optional K, M or G");
}

std::string format_size(std::size_t bytes) {
  if (bytes >= (1u << 20) && bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= (1u << 10) && bytes % (1u << 10) == 0) return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + " B";
}

Throughput throughput_of(std::int64_t first_sent_ns, std::int64_t last_received_ns,
                         std::uint64_t received, std::uint64_t published) {
  Throughput result;
  result.published = published;
  result.received = received;
  const double seconds = static_cast<double>(last_received_ns - first_sent_ns) / 1e9;
  result.messages_per_s = seconds > 0 ? static_cast<double>(received) / seconds : 0;
  return result;
}

}  // namespace agnocast::bench
