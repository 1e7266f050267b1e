// Naming rules shared by the library, the daemon and the CLI: topic names, the
// notification queue that belongs to each callback subscriber, and the two
// topics that carry each service.
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

// A service "/arm/enable" travels on two topics: clients publish requests on
// "/_service_request/arm/enable", where its one server subscribes, and the
// server publishes each response on "/_service_reply/arm/enable" to the one
// client that asked. Applications cannot create endpoints under these two
// prefixes, and topic and queue listings leave them out.
inline constexpr std::string_view service_request_prefix = "/_service_request";
inline constexpr std::string_view service_reply_prefix = "/_service_reply";
// A service name follows the topic rules, with room left for the longer prefix.
inline constexpr std::size_t service_name_max = topic_name_max - service_request_prefix.size();

// Empty when the name is a valid service name, else a sentence naming the broken rule.
std::string service_name_problem(std::string_view service);
// Throws std::invalid_argument naming the rule the service name breaks.
void validate_service_name(std::string_view service);
std::string service_request_topic(std::string_view service);
std::string service_reply_topic(std::string_view service);

enum class ServiceTopicRole { request, reply };
struct ServiceTopic {
  std::string service;  // "/arm/enable"
  ServiceTopicRole role = ServiceTopicRole::request;
};
// Which service a topic carries, or nullopt for an application topic.
std::optional<ServiceTopic> service_of_topic(std::string_view topic);
// Whether the topic is reserved for services (applications may not use it).
bool is_service_topic(std::string_view topic);

}  // namespace agnocast
