// Read-only view of the kernel module's state for tools (agnocast-cli).
// These functions open /dev/agnocast on their own, never register the calling
// process, and throw ModuleNotLoaded when the module is absent.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "agnocast/version.hpp"

namespace agnocast {

// The device the module creates (the UAPI's AGNOCAST_DEVICE_PATH); C strings
// for the system calls that take them.
inline constexpr char device_path[] = "/dev/agnocast";
// There as soon as the module is in the kernel, before the device appears.
inline constexpr char module_sysfs_directory[] = "/sys/module/agnocast";

struct TopicSummary {
  std::string name;
  std::uint32_t publishers = 0;
  std::uint32_t subscribers = 0;
  std::string type_name;  // the message type its first endpoint fixed
  std::uint64_t type_hash = 0;
};

struct PublisherInfo {
  std::uint32_t id = 0;
  pid_t pid = 0;
  std::string node;
  std::uint32_t depth = 0;
  bool transient_local = false;
  std::uint64_t published = 0;
  std::uint64_t published_bytes = 0;
  std::uint32_t window = 0;  // entries currently in the publisher's depth window
  uid_t uid = 0;             // the publishing process's effective uid
};

struct SubscriberInfo {
  std::uint32_t id = 0;
  pid_t pid = 0;
  std::string node;
  std::uint32_t depth = 0;
  bool transient_local = false;
  bool polling = false;  // polling subscribers own no notification queue
  std::uint32_t unreceived = 0;
  std::uint32_t held = 0;
  std::uint64_t received = 0;
  std::uint64_t dropped = 0;
  uid_t uid = 0;  // the subscribing process's effective uid
};

struct TopicInfo {
  std::string name;
  std::vector<PublisherInfo> publishers;
  std::vector<SubscriberInfo> subscribers;
  std::uint32_t entries = 0;  // live message entries of the topic
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::uint32_t schema_size = 0;  // bytes of the registered schema, 0 when none
};

struct ProcessInfo {
  pid_t pid = 0;
  std::uint32_t publishers = 0;
  std::uint32_t subscribers = 0;
  std::uint32_t pools_mapped = 0;
  std::uint64_t pool_addr = 0;
  std::uint64_t pool_size = 0;
};

// The callback subscriber a notification queue belongs to.
struct QueueOwner {
  std::string topic;
  std::uint32_t subscriber_id = 0;
  pid_t pid = 0;
};

// Queue name ("/a_b@3") -> its owner, for every callback subscriber of
// `topics` (a polling subscriber owns no queue): the queues that are live.
std::map<std::string, QueueOwner> queue_owners(const std::vector<TopicInfo>& topics);

// True when /dev/agnocast exists.
bool module_loaded();
// The loaded module's version, nullopt when it is not loaded.
std::optional<Version> module_version();
std::vector<TopicSummary> list_topics();
// nullopt when no topic of that name has an endpoint.
std::optional<TopicInfo> topic_info(const std::string& topic);
std::vector<ProcessInfo> list_processes();
// The schema blob the topic's endpoints registered (see schema.hpp);
// nullopt when it has none or no such topic has an endpoint.
std::optional<std::vector<std::uint8_t>> topic_schema(const std::string& topic);
// queue_owners() of every topic the module lists now.
std::map<std::string, QueueOwner> live_queue_owners();

// The delays, from publish() to the start of the callback, that a process
// recorded for one of its callback subscribers (agnocast-cli topic delay).
struct RecordedDelays {
  std::uint64_t count = 0;              // recorded since the subscriber began
  std::vector<std::int64_t> newest_ns;  // the newest of them (at most 1,024), oldest first
};
// nullopt when the process keeps none for that subscriber: a polling one, a
// process gone or of another start, or a record that is missing or malformed.
// Reads a file of the process's, not the module.
std::optional<RecordedDelays> recorded_delays(pid_t pid, const std::string& topic,
                                              std::uint32_t subscriber_id);
// The pids whose processes made such a record (a file each in /dev/shm).
std::vector<pid_t> delay_record_pids();
// Removes the record of `pid` when no live process made it: its maker died
// (and the pid may be another process's now). With `exit_reported` (the
// module's exit record named the pid), a process of the pid still on its way
// out counts as gone. True when it was removed.
bool remove_stale_delay_record(pid_t pid, bool exit_reported = false);

}  // namespace agnocast
