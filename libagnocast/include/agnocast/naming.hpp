// Naming rules shared by the library, the daemon and the CLI: topic names and
// the notification queue that belongs to each callback subscriber.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "agnocast/limits.hpp"

namespace agnocast {

// The notification a publisher sends to a subscriber's queue. Its content is
// irrelevant: receiving it means "ask the kernel what there is to receive".
struct MqMsgAgnocast {
  bool dummy;
};

// Where the mqueue filesystem is mounted; a queue "/x@1" is the file "/dev/mqueue/x@1".
inline constexpr std::string_view mqueue_directory = "/dev/mqueue";

// Empty when the name is valid, else a sentence naming the broken rule. Its
// length is bounded by topic_name_max (<agnocast/limits.hpp>).
std::string topic_name_problem(std::string_view topic);
bool is_valid_topic_name(std::string_view topic);
// Throws std::invalid_argument naming the rule the topic breaks.
void validate_topic_name(std::string_view topic);

// "/a/b/c" -> "/a_b_c": every '/' after the leading one becomes '_'.
std::string mangle_topic_name(std::string_view topic);
// "/a/b", 3 -> "/a_b@3", the name to pass to mq_open.
std::string queue_name(std::string_view topic, std::uint32_t subscriber_id);

struct QueueNameParts {
  std::string mangled_topic;  // with its leading '/', e.g. "/a_b"
  std::uint32_t subscriber_id = 0;
};
// Accepts "/a_b@3" (mq_open form) or "a_b@3" (a file name in mqueue_directory);
// nullopt when it does not follow the agnocast pattern.
std::optional<QueueNameParts> parse_queue_name(std::string_view name);

}  // namespace agnocast
