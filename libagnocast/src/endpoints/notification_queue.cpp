#include "endpoints/notification_queue.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>

#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"
#include "log_internal.hpp"

namespace agnocast::detail {
namespace {

constexpr std::size_t max_cached_senders = 256;
// Publishers of every user may wake us (a spurious wake-up only costs a
// RECEIVE that finds nothing); nobody but us may take our wake-ups.
constexpr mode_t queue_mode = 0622;

// The queues this process owns, for OwnedQueue::wake_all().
std::mutex owned_mutex;
std::set<const OwnedQueue*>& owned_queues() {
  static auto* queues = new std::set<const OwnedQueue*>;  // outlives static destructors
  return *queues;
}

std::string creation_advice(int err) {
  switch (err) {
    case ENOSPC:
      return "the system-wide number of message queues is at fs.mqueue.queues_max; raise it "
             "(sysctl fs.mqueue.queues_max=N)";
    case EMFILE:
      return "this process reached its limit on open descriptors (RLIMIT_NOFILE) or on queue "
             "memory (RLIMIT_MSGQUEUE, ulimit -q); raise the limit";
    case ENFILE:
      return "the system-wide limit on open files was reached (fs.file-max)";
    case EINVAL:
      return "the queue size exceeds fs.mqueue.msg_max or fs.mqueue.msgsize_max; raise them "
             "(sysctl fs.mqueue.msg_max=N)";
    case ENAMETOOLONG:
      return "the queue name exceeds NAME_MAX (255)";
    case EACCES:
      return "permission denied";
    default:
      return std::strerror(err);
  }
}

}  // namespace

long system_msg_max() {
  std::ifstream file("/proc/sys/fs/mqueue/msg_max");
  long value = 0;
  if (file >> value && value > 0) return value;
  return 10;  // the Linux default
}

OwnedQueue::OwnedQueue(const std::string& name, std::size_t depth)
    : name_(name), descriptor_(-1), owner_pid_(::getpid()) {
  mq_attr attributes{};
  // Room for two at least, so that a wake-up can take its notification after
  // its callbacks (see drains_after()).
  attributes.mq_maxmsg = std::min(std::max(static_cast<long>(depth), 2L), system_msg_max());
  capacity_ = attributes.mq_maxmsg;
  attributes.mq_msgsize = sizeof(MqMsgAgnocast);
  // Read-write: only the creator may open it so (mode 0622), and sending to
  // itself then needs no other descriptor.
  const int flags = O_RDWR | O_NONBLOCK | O_CREAT | O_EXCL | O_CLOEXEC;
  descriptor_ = ::mq_open(name.c_str(), flags, queue_mode, &attributes);
  if (descriptor_ == -1 && errno == EEXIST) {
    // The kernel never gives a live subscriber's id twice for a name, so this
    // queue is a leftover nobody owns: replace it.
    ::mq_unlink(name.c_str());
    descriptor_ = ::mq_open(name.c_str(), flags, queue_mode, &attributes);
  }
  if (descriptor_ == -1) {
    const int err = errno;
    throw QueueError(err, "agnocast: cannot create notification queue " + name + ": " +
                              creation_advice(err) + " (" + std::strerror(err) + ")");
  }
  // mq_open applies the umask: set the mode itself.
  if (::fchmod(descriptor_, queue_mode) != 0) {
    const int err = errno;
    ::mq_close(descriptor_);
    ::mq_unlink(name.c_str());
    throw QueueError(err, "agnocast: cannot set the mode of notification queue " + name + " (" +
                              std::strerror(err) + ")");
  }
  std::lock_guard lock(owned_mutex);
  owned_queues().insert(this);
}

OwnedQueue::~OwnedQueue() {
  {
    std::lock_guard lock(owned_mutex);
    owned_queues().erase(this);
  }
  ::mq_close(descriptor_);
  // A fork child shares the descriptor but not the ownership.
  if (::getpid() == owner_pid_) ::mq_unlink(name_.c_str());
}

bool OwnedQueue::take_one() const {
  char buffer[sizeof(MqMsgAgnocast)];
  for (;;) {
    if (::mq_receive(descriptor_, buffer, sizeof buffer, nullptr) >= 0) return true;
    if (errno != EINTR) return false;
  }
}

void OwnedQueue::notify() const {
  const MqMsgAgnocast message{};
  while (::mq_send(descriptor_, reinterpret_cast<const char*>(&message), sizeof message, 0) != 0 &&
         errno == EINTR) {
  }
}

void OwnedQueue::wake_all() {
  const pid_t pid = ::getpid();
  std::lock_guard lock(owned_mutex);
  for (const OwnedQueue* queue : owned_queues()) {
    // A fork child's copies are its parent's to wake.
    if (queue->owner_pid_ == pid) queue->notify();
  }
}

QueueSenders::~QueueSenders() {
  for (const auto& [id, descriptor] : descriptors_) ::mq_close(descriptor);
}

bool QueueSenders::notify(std::uint32_t subscriber_id) {
  auto found = descriptors_.find(subscriber_id);
  if (found == descriptors_.end()) {
    const mqd_t descriptor =
        ::mq_open(queue_name(topic_, subscriber_id).c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (descriptor == -1) {
      // ENOENT: not created yet (the subscriber wakes itself once it has
      // made it), or removed under a live subscriber.
      if (errno != ENOENT) {
        log(LogLevel::warning, "cannot open the notification queue " +
                                   queue_name(topic_, subscriber_id) +
                                   " to wake its subscriber: " + std::strerror(errno));
      }
      return false;
    }
    // Ids of gone subscribers are never reused, so the cache only grows; bound it.
    if (descriptors_.size() >= max_cached_senders) {
      for (const auto& [id, cached] : descriptors_) ::mq_close(cached);
      descriptors_.clear();
    }
    found = descriptors_.emplace(subscriber_id, descriptor).first;
  }
  const MqMsgAgnocast message{};
  for (;;) {
    if (::mq_send(found->second, reinterpret_cast<const char*>(&message), sizeof message, 0) == 0) {
      return true;
    }
    if (errno == EINTR) continue;
    // Full: a wake-up is already waiting, which is all a notification says.
    if (errno == EAGAIN) return true;
    log(LogLevel::warning,
        "cannot notify " + queue_name(topic_, subscriber_id) + ": " + std::strerror(errno));
    // Opened afresh next time.
    ::mq_close(found->second);
    descriptors_.erase(found);
    return false;
  }
}

}  // namespace agnocast::detail
