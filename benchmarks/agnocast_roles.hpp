// agnocast's side of the benchmark: publisher and subscriber processes forked
// from the driver, which itself never touches agnocast.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace agnocast::bench {

// One-way latency of `count` messages of `size` payload bytes to each of
// `subscribers` callback subscribers, one message in flight at a time; the
// result holds one latency vector per subscriber (warm-up messages removed).
// With scratch_bytes, the publisher also writes that many bytes of private
// memory before each message: a control for what writing a large payload
// does to the caches, apart from the payload's size itself.
std::vector<std::vector<std::int64_t>> run_agnocast_latency(std::size_t size, std::size_t count,
                                                            std::size_t subscribers,
                                                            std::size_t scratch_bytes = 0);

struct Throughput {
  double messages_per_s = 0;
  std::uint64_t received = 0;
  std::uint64_t published = 0;
};
// `count` small messages published back to back to one subscriber.
Throughput run_agnocast_throughput(std::size_t size, std::size_t count);

}  // namespace agnocast::bench
