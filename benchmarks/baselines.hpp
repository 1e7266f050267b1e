// The yardsticks agnocast is measured against in the same VM boot: the bare
// notification path it is built on, and a transport that copies the bytes.
#pragma once

#include <cstddef>

#include "bench_support.hpp"

namespace agnocast::bench {

// One-way time of a 1-byte POSIX message queue ping-pong (round trip / 2).
LatencyStats run_mqueue_floor(std::size_t count);

// Send start to receive end of `size` bytes over a Unix stream socket.
LatencyStats run_unix_socket_copy(std::size_t size, std::size_t count);

}  // namespace agnocast::bench
