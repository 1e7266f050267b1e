#include "call_timer.hpp"

#include <agnocast.h>
#include <mqueue.h>
#include <sys/epoll.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdarg>
#include <cstdio>

#include "bench_support.hpp"

namespace agnocast::bench {
namespace {

std::vector<TimedCall> calls;
bool recording = false;

void keep(CallKind kind, std::int64_t detail, std::int64_t start_ns, std::int64_t end_ns) {
  if (recording && calls.size() < calls.capacity()) {
    calls.push_back({kind, detail, start_ns, end_ns});
  }
}

}  // namespace

void start_recording(std::size_t capacity) {
  calls.clear();
  calls.reserve(capacity);
  recording = true;
}

void stop_recording() { recording = false; }

const std::vector<TimedCall>& recorded_calls() { return calls; }

void mark(std::int64_t what, std::int64_t start_ns, std::int64_t end_ns) {
  keep(CallKind::mark, what, start_ns, end_ns);
}

std::string call_name(const TimedCall& call) {
  switch (call.kind) {
    case CallKind::mq_send:
      return "mq_send";
    case CallKind::mq_receive:
      return "mq_receive";
    case CallKind::epoll_wait:
      return call.detail == 0 ? "epoll_wait (poll)" : "epoll_wait";
    case CallKind::mark:
      return "mark";
    case CallKind::ioctl:
      break;
  }
  const auto request = static_cast<unsigned long>(call.detail);
  if (request == AGNOCAST_IOC_PUBLISH) return "ioctl PUBLISH";
  if (request == AGNOCAST_IOC_RECEIVE) return "ioctl RECEIVE";
  if (request == AGNOCAST_IOC_RELEASE) return "ioctl RELEASE";
  if (request == AGNOCAST_IOC_RECLAIM) return "ioctl RECLAIM";
  if (request == AGNOCAST_IOC_TAKE) return "ioctl TAKE";
  if (request == AGNOCAST_IOC_SHED) return "ioctl SHED";
  if (request == AGNOCAST_IOC_GET_VERSION) return "ioctl GET_VERSION";
  char text[32];
  std::snprintf(text, sizeof text, "ioctl 0x%lx", request);
  return text;
}

}  // namespace agnocast::bench

namespace bench = agnocast::bench;

// The C library's entry points, made here as raw system calls.  A call made
// while recording costs two clock reads (the vDSO, no system call) more.
extern "C" {

int ioctl(int fd, unsigned long request, ...) {
  va_list arguments;
  va_start(arguments, request);
  void* argument = va_arg(arguments, void*);
  va_end(arguments);
  const std::int64_t start = bench::now_ns();
  const auto result = static_cast<int>(syscall(SYS_ioctl, fd, request, argument));
  bench::keep(bench::CallKind::ioctl, static_cast<std::int64_t>(request), start, bench::now_ns());
  return result;
}

}  // extern "C"

namespace {

int send_timed(mqd_t queue, const char* message, size_t size, unsigned priority,
               const struct timespec* deadline) {
  const std::int64_t start = bench::now_ns();
  const auto result =
      static_cast<int>(syscall(SYS_mq_timedsend, queue, message, size, priority, deadline));
  bench::keep(bench::CallKind::mq_send, 0, start, bench::now_ns());
  return result;
}

ssize_t receive_timed(mqd_t queue, char* message, size_t size, unsigned* priority,
                      const struct timespec* deadline) {
  const std::int64_t start = bench::now_ns();
  const auto result = syscall(SYS_mq_timedreceive, queue, message, size, priority, deadline);
  bench::keep(bench::CallKind::mq_receive, 0, start, bench::now_ns());
  return result;
}

}  // namespace

extern "C" {

int mq_timedsend(mqd_t queue, const char* message, size_t size, unsigned priority,
                 const struct timespec* deadline) {
  return send_timed(queue, message, size, priority, deadline);
}

int mq_send(mqd_t queue, const char* message, size_t size, unsigned priority) {
  return send_timed(queue, message, size, priority, nullptr);
}

ssize_t mq_timedreceive(mqd_t queue, char* message, size_t size, unsigned* priority,
                        const struct timespec* deadline) {
  return receive_timed(queue, message, size, priority, deadline);
}

ssize_t mq_receive(mqd_t queue, char* message, size_t size, unsigned* priority) {
  return receive_timed(queue, message, size, priority, nullptr);
}

int epoll_wait(int epoll_fd, struct epoll_event* events, int capacity, int timeout_ms) {
  const std::int64_t start = bench::now_ns();
  const auto result =
      static_cast<int>(syscall(SYS_epoll_wait, epoll_fd, events, capacity, timeout_ms));
  bench::keep(bench::CallKind::epoll_wait, timeout_ms, start, bench::now_ns());
  return result;
}

}  // extern "C"
