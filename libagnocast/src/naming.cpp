#include "agnocast/naming.hpp"

#include <charconv>
#include <stdexcept>

namespace agnocast {
namespace {

bool is_topic_character(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '/';
}

}  // namespace

std::string topic_name_problem(std::string_view topic) {
  const std::string quoted = "topic name '" + std::string(topic) + "' ";
  if (topic.empty() || topic.front() != '/') return quoted + "must start with '/'";
  for (char c : topic) {
    if (!is_topic_character(c)) return quoted + "may contain only A-Z a-z 0-9 _ and /";
  }
  if (topic.find("//") != std::string_view::npos) return quoted + "must not contain \"//\"";
  if (topic.size() > 1 && topic.back() == '/') return quoted + "must not end with '/'";
  if (topic.size() == 1) return quoted + "must name something after '/'";
  if (topic.size() > topic_name_max) {
    return quoted + "is too long: at most " + std::to_string(topic_name_max) +
           " characters, so that its notification queue name fits NAME_MAX (" +
           std::to_string(queue_name_max) + ")";
  }
  return {};
}

bool is_valid_topic_name(std::string_view topic) { return topic_name_problem(topic).empty(); }

void validate_topic_name(std::string_view topic) {
  if (std::string problem = topic_name_problem(topic); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
}

std::string mangle_topic_name(std::string_view topic) {
  std::string mangled(topic);
  for (std::size_t i = 1; i < mangled.size(); ++i) {
    if (mangled[i] == '/') mangled[i] = '_';
  }
  return mangled;
}

std::string queue_name(std::string_view topic, std::uint32_t subscriber_id) {
  return mangle_topic_name(topic) + "@" + std::to_string(subscriber_id);
}

std::optional<QueueNameParts> parse_queue_name(std::string_view name) {
  if (!name.empty() && name.front() == '/') name.remove_prefix(1);
  const std::size_t at = name.rfind('@');
  if (at == std::string_view::npos || at == 0) return std::nullopt;
  const std::string_view digits = name.substr(at + 1);
  if (digits.empty() || digits.size() > subscriber_id_digits_max) return std::nullopt;
  if (digits.size() > 1 && digits.front() == '0') return std::nullopt;
  QueueNameParts parts;
  const auto [end, error] =
      std::from_chars(digits.data(), digits.data() + digits.size(), parts.subscriber_id);
  if (error != std::errc{} || end != digits.data() + digits.size()) return std::nullopt;
  parts.mangled_topic = '/';
  parts.mangled_topic += name.substr(0, at);
  // A mangled topic is a valid topic without inner '/'.
  if (parts.mangled_topic.find('/', 1) != std::string::npos ||
      !is_valid_topic_name(parts.mangled_topic)) {
    return std::nullopt;
  }
  return parts;
}

namespace {

// The rest of the topic after prefix when prefix is its first component(s), else nullopt.
std::optional<std::string_view> below_prefix(std::string_view topic, std::string_view prefix) {
  if (!topic.starts_with(prefix)) return std::nullopt;
  const std::string_view rest = topic.substr(prefix.size());
  if (!rest.empty() && rest.front() != '/') return std::nullopt;
  return rest;
}

}  // namespace

std::string service_name_problem(std::string_view service) {
  std::string problem = topic_name_problem(service);
  if (!problem.empty()) {
    const std::string_view topic_word = "topic name";
    if (problem.starts_with(topic_word)) problem.replace(0, topic_word.size(), "service name");
    return problem;
  }
  if (service.size() > service_name_max) {
    return "service name '" + std::string(service) + "' is too long: at most " +
           std::to_string(service_name_max) + " characters, so that its request topic fits";
  }
  if (is_service_topic(service)) {
    return "service name '" + std::string(service) + "' must not start with " +
           std::string(service_request_prefix) + " or " + std::string(service_reply_prefix);
  }
  return {};
}

void validate_service_name(std::string_view service) {
  if (std::string problem = service_name_problem(service); !problem.empty()) {
    throw std::invalid_argument(problem);
  }
}

std::string service_request_topic(std::string_view service) {
  return std::string(service_request_prefix) + std::string(service);
}

std::string service_reply_topic(std::string_view service) {
  return std::string(service_reply_prefix) + std::string(service);
}

std::optional<ServiceTopic> service_of_topic(std::string_view topic) {
  if (auto rest = below_prefix(topic, service_request_prefix); rest && !rest->empty()) {
    return ServiceTopic{std::string(*rest), ServiceTopicRole::request};
  }
  if (auto rest = below_prefix(topic, service_reply_prefix); rest && !rest->empty()) {
    return ServiceTopic{std::string(*rest), ServiceTopicRole::reply};
  }
  return std::nullopt;
}

bool is_service_topic(std::string_view topic) {
  return below_prefix(topic, service_request_prefix).has_value() ||
         below_prefix(topic, service_reply_prefix).has_value();
}

}  // namespace agnocast
