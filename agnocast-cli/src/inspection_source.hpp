// Everything the CLI reads from the system, behind one interface so that the
// commands are pure functions of it and unit tests can feed them fake state.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "agnocast/access_policy.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/version.hpp"

namespace agnocast::cli {

// A polling subscription whose message type is known only from the schema the
// topic's endpoints registered (topic echo).
class MessageTap {
 public:
  // The message in place and the only bytes a reader may touch (the publisher's pool).
  using Reader = std::function<void(const void* message, std::span<const std::byte> readable)>;

  virtual ~MessageTap() = default;
  virtual const Schema& schema() const = 0;
  // Runs `read` on the newest message not taken yet, held meanwhile; false when none.
  virtual bool take(const Reader& read) = 0;
};

// What mq_getattr says of a queue, read without consuming anything.
struct QueueAttributes {
  long pending = 0;   // mq_curmsgs
  long capacity = 0;  // mq_maxmsg
};

class InspectionSource {
 public:
  virtual ~InspectionSource() = default;

  // Kernel module state through libagnocast's inspection API.
  // nullopt when the module is not loaded.
  virtual std::optional<Version> module_version() = 0;
  // These throw agnocast::ModuleNotLoaded when the module is absent.
  virtual std::vector<TopicSummary> list_topics() = 0;
  virtual std::optional<TopicInfo> topic_info(const std::string& topic) = 0;
  // Every process registered with the module in this IPC namespace.
  virtual std::vector<ProcessInfo> list_processes() = 0;
  // The topic access policy in force; nullopt when there is none.
  virtual std::optional<AccessPolicy> access_policy() = 0;

  // Names from the passwd and group databases; nullopt when an id has none.
  virtual std::optional<std::string> user_name(std::uint32_t uid) = 0;
  virtual std::optional<std::string> group_name(std::uint32_t gid) = 0;

  // File names (without the leading '/') of every queue in the mqueue directory.
  virtual std::vector<std::string> queue_files() = 0;
  // nullopt when the queue does not exist or this user may not open it.
  virtual std::optional<QueueAttributes> queue_attributes(const std::string& queue_name) = 0;

  virtual bool path_exists(const std::string& path) = 0;
  // 0 when access(path, mode) succeeds, else the errno.
  virtual int path_access(const std::string& path, int mode) = 0;
  // nullopt when the file cannot be read.
  virtual std::optional<std::string> read_file(const std::string& path) = 0;
  virtual bool process_alive(pid_t pid) = 0;
  // Whether another process holds an exclusive flock on the file (tested with
  // a non-blocking shared lock on a read-only descriptor); nullopt when the
  // file cannot be opened.
  virtual std::optional<bool> exclusively_locked(const std::string& path) = 0;

  // Subscribes to `topic` with the type its endpoints registered; throws
  // agnocast::TopicWithoutSchema when it has no endpoint or no schema.
  virtual std::unique_ptr<MessageTap> subscribe(const std::string& topic) = 0;
  // The schema `topic`'s endpoints registered, without subscribing; throws
  // like subscribe().
  virtual Schema topic_schema(const std::string& topic) = 0;
  // The publish → callback-start delays a process recorded for one of its
  // subscribers; nullopt when it keeps none for it.
  virtual std::optional<RecordedDelays> recorded_delays(pid_t pid, const std::string& topic,
                                                        std::uint32_t subscriber_id) = 0;
  // True once SIGINT or SIGTERM asked a streaming command to stop.
  virtual bool stop_requested() = 0;

  // Monotonic seconds and a sleep, for sampling counters over a window.
  virtual double now_seconds() = 0;
  // Seconds since the Unix epoch, for timestamps other programs wrote.
  virtual double unix_time() = 0;
  virtual void sleep_seconds(double seconds) = 0;
};

// The real system: libagnocast, /dev/mqueue, /proc, the clock.
InspectionSource& system_source();

}  // namespace agnocast::cli
