// Times the system calls libagnocast makes, in place: this program defines
// ioctl, mq_send, mq_receive, mq_timedsend, mq_timedreceive and epoll_wait,
// which the library (a shared object) then calls instead of the C library's.
// Each makes the raw system call and, while recording is on, keeps its
// start and end on the monotonic clock.  Only agnocast-bench-breakdown links
// this: the other measurements run the C library's calls untouched.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace agnocast::bench {

enum class CallKind : std::int64_t { ioctl, mq_send, mq_receive, epoll_wait, mark };

struct TimedCall {
  CallKind kind;
  // ioctl: the request; epoll_wait: the timeout (ms); mark: what the
  // benchmark marked.
  std::int64_t detail;
  std::int64_t start_ns;
  std::int64_t end_ns;
};

// Starts keeping calls (at most `capacity`, allocated now, none while recording).
void start_recording(std::size_t capacity);
void stop_recording();
const std::vector<TimedCall>& recorded_calls();

// A point or span of the benchmark's own code on the same timeline.
void mark(std::int64_t what, std::int64_t start_ns, std::int64_t end_ns);

// "PUBLISH", "RECEIVE", "mq_send"...: the name a call is reported under.
std::string call_name(const TimedCall& call);

}  // namespace agnocast::bench
