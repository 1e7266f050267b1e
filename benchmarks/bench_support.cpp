#include "bench_support.hpp"

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
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

namespace {
std::uint8_t pattern_byte(std::uint64_t seq, std::size_t index) {
  return static_cast<std::uint8_t>((seq * 131 + index * 7 + (index >> 12)) & 0xff);
}
}  // namespace

void fill_payload(std::span<std::uint8_t> payload, std::uint64_t seq) {
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = pattern_byte(seq, i);
}

bool payload_intact(std::span<const std::uint8_t> payload, std::uint64_t seq) {
  for (std::size_t i = 0; i < payload.size(); ++i) {
    if (payload[i] != pattern_byte(seq, i)) return false;
  }
  return true;
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

}  // namespace agnocast::bench
