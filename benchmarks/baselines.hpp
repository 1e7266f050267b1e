// The yardsticks agnocast is measured against in the same VM boot: the bare
// notification path it is built on, and a transport that copies the bytes.
#pragma once

#include <cstddef>

#include "bench_support.hpp"

namespace agnocast::bench {

// How a floor's receiver sleeps: in mq_receive itself, or in epoll_wait on
// the queue and then mq_receive, as agnocast's executor does.
enum class FloorWait { blocking, epoll };

// One-way times (ns) of a 1-byte POSIX message queue ping-pong: send to
// the receiver's return from mq_receive, the sender having just woken as a
// publisher has.
std::vector<std::int64_t> run_mqueue_floor(std::size_t count, FloorWait wait,
                                           std::size_t scratch_bytes = 0);

// Send of the first to the last receiver's return (ns): one process sends a
// 1-byte message to each of `receivers` queues, each with its own receiver
// process waiting in epoll.  The floor of agnocast's fan-out.
std::vector<std::int64_t> run_mqueue_fanout(std::size_t receivers, std::size_t count);

// Send start to receive end (ns) of `size` bytes over a Unix stream socket,
// the sender writing `scratch_bytes` of private memory before each message.
std::vector<std::int64_t> run_unix_socket_copy(std::size_t size, std::size_t count,
                                               std::size_t scratch_bytes);

// Request to response over a Unix SOCK_SEQPACKET socket pair between two
// processes, one byte each way, each side asleep in epoll_wait before it
// reads, as agnocast's executor is: from the client's send to its return
// from reading the answer (ns).  The floor of a service's round trip.
std::vector<std::int64_t> run_unix_socket_request_response(std::size_t count);

// User + system CPU of each side of the epoll floor per message, one
// message a millisecond, over `count` messages after a warm-up.
CpuPerMessage run_mqueue_floor_cpu(std::size_t count);

}  // namespace agnocast::bench
