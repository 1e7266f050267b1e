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

// Sleeps until a CLOCK_MONOTONIC time: fixed-rate loops pace with it.
void sleep_until_ns(std::int64_t deadline_ns);

// User + system CPU time this process has used, in nanoseconds.
std::int64_t cpu_time_ns();

// Bytes written before each sample besides the payload, so that every payload
// size is preceded by the same number of written bytes (payload +
// scratch = 64 MiB).  Shared memory (a memfd), the kind the zero-copy
// transports' payloads live in.
class SharedScratch {
 public:
  explicit SharedScratch(std::size_t bytes);
  ~SharedScratch();
  SharedScratch(const SharedScratch&) = delete;
  SharedScratch& operator=(const SharedScratch&) = delete;
  std::span<std::uint8_t> bytes() { return {data_, size_}; }

 private:
  std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

// Fixed-rate runs (CPU time and system calls per message): one message a
// millisecond; the first few are not counted.
constexpr std::int64_t steady_period_ns = 1'000'000;
constexpr std::size_t steady_warmup_messages = 5;

struct CpuPerMessage {
  double publisher_us = 0;
  double subscriber_us = 0;
};
CpuPerMessage per_message(std::int64_t publisher_ns, std::int64_t subscriber_ns,
                          std::size_t messages);

// Every sample of the size series writes this many bytes in all.
constexpr std::size_t constant_written_bytes = std::size_t{64} << 20;

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

// Messages sent back to back: how many the receiver got, over the time from
// the first one's send to the last one's arrival.
struct Throughput {
  double messages_per_s = 0;
  std::uint64_t received = 0;
  std::uint64_t published = 0;
};
Throughput throughput_of(std::int64_t first_sent_ns, std::int64_t last_received_ns,
                         std::uint64_t received, std::uint64_t published);

// Parses "64", "4K", "1M" (binary units).
std::size_t parse_size(const std::string& text);
std::string format_size(std::size_t bytes);

}  // namespace agnocast::bench
