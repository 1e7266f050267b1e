// The yardsticks agnocast is measured against in the same VM boot: the bare
// notification path it is built on, and a transport that copies the bytes.
#pragma once

#include <cstddef>

#include "bench_support.hpp"

namespace agnocast::bench {

// One-way times (ns) of a 1-byte POSIX message queue ping-pong: send to
// the receiver's return, the sender having just woken as a publisher has.
std::vector<std::int64_t> run_mqueue_floor(std::size_t count);

// Send start to receive end (ns) of `size` bytes over a Unix stream socket.
std::vector<std::int64_t> run_unix_socket_copy(std::size_t size, std::size_t count);

}  // namespace agnocast::bench
