// What every benchmark role shares: the clock, payload patterns, latency
// statistics and the pipes that carry acks and results between processes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace agnocast::bench {

// CLOCK_MONOTONIC in nanoseconds: one clock for every process on the machine.
std::int64_t now_ns();

// Pause between two measured messages, outside the measured interval, so the
// receiver is back asleep (and its CPU idle) when the next one is sent: each
// sample then measures a wake-up from sleep, not the tail of the last message.
void settle_between_messages();

// Payload bytes derived from the message sequence number, so a reader can tell
// a whole, untouched message from a corrupted or reused one.
void fill_payload(std::span<std::uint8_t> payload, std::uint64_t seq);
bool payload_intact(std::span<const std::uint8_t> payload, std::uint64_t seq);

struct LatencyStats {
  std::size_t samples = 0;
  double p50_us = 0;
  double p99_us = 0;
};
LatencyStats summarize(std::vector<std::int64_t> latencies_ns);

// A pipe between two processes of one benchmark run.
struct Pipe {
  int read_fd = -1;
  int write_fd = -1;
  static Pipe open();
  void close_read();
  void close_write();
};
void write_all(int fd, const void* data, std::size_t size);
// False on end of file before size bytes.
bool read_all(int fd, void* data, std::size_t size);
void send_latencies(int fd, const std::vector<std::int64_t>& latencies_ns);
std::vector<std::int64_t> receive_latencies(int fd);

// Parses "64", "4K", "1M" (binary units).
std::size_t parse_size(const std::string& text);
std::string format_size(std::size_t bytes);

}  // namespace agnocast::bench
