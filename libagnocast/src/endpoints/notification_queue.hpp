// The POSIX message queues that carry "something new for you".
#pragma once

#include <mqueue.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace agnocast::detail {

// The receiving end a callback subscriber creates and owns; unlinked on
// destruction. It also sends to itself, through its own descriptor, so that
// waking itself needs no descriptor more (the process may have none left).
class OwnedQueue {
 public:
  // Creates name for depth notifications (two at least, capped by
  // fs.mqueue.msg_max), replacing a stale queue of that name. Throws
  // QueueError naming the limit hit.
  OwnedQueue(const std::string& name, std::size_t depth);
  ~OwnedQueue();
  OwnedQueue(const OwnedQueue&) = delete;
  OwnedQueue& operator=(const OwnedQueue&) = delete;

  int fd() const { return descriptor_; }
  const std::string& name() const { return name_; }
  // Takes one notification without blocking; false when there was none.
  bool take_one() const;
  // Whether a wake-up may take its notification after receiving: a full
  // queue refuses a notification only while it holds two, so one still
  // waits after the one that woke us is taken.
  bool drains_after() const { return capacity_ >= 2; }
  // Queues one notification to ourselves (never blocks; a full queue is fine).
  void notify() const;
  // Notifies every queue this process owns: the kernel's wake_fd() said a
  // notification to one of them may have been lost. A wake-up that finds
  // nothing costs one RECEIVE.
  static void wake_all();

 private:
  std::string name_;
  mqd_t descriptor_;
  pid_t owner_pid_;
  long capacity_ = 0;
};

// A publisher's sending ends, opened on first use and kept per subscriber id.
class QueueSenders {
 public:
  explicit QueueSenders(std::string topic) : topic_(std::move(topic)) {}
  ~QueueSenders();
  QueueSenders(const QueueSenders&) = delete;
  QueueSenders& operator=(const QueueSenders&) = delete;

  // Never blocks and never throws. True when the subscriber has a wake-up
  // waiting: sent now, or already there (a full queue). False when the queue
  // could not be opened or the send failed: the caller reports it to the
  // kernel (Kernel::notify_failed), which wakes the subscriber another way.
  bool notify(std::uint32_t subscriber_id);

 private:
  std::string topic_;
  std::map<std::uint32_t, mqd_t> descriptors_;
};

// The system's fs.mqueue.msg_max (what an unprivileged queue may hold).
long system_msg_max();

}  // namespace agnocast::detail
