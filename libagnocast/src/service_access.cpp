#include "agnocast/service_access.hpp"

#include <stdexcept>

#include "agnocast/naming.hpp"

namespace agnocast {
namespace {

// The service rule that topic_rules_of() turns into exactly these two rules, if any.
std::optional<ServiceAccessRule> service_rule_of(const AccessRule& request,
                                                 const AccessRule& reply) {
  if (!request.topics.starts_with(service_request_prefix)) return std::nullopt;
  ServiceAccessRule rule{request.topics.substr(service_request_prefix.size()), request.subscribe,
                         request.publish};
  try {
    if (topic_rules_of(rule) == std::array{request, reply}) return rule;
  } catch (const std::invalid_argument&) {
    // Not a service pattern: a topic rule under the reserved prefix.
  }
  return std::nullopt;
}

}  // namespace

TopicPattern parse_service_pattern(std::string_view pattern) {
  TopicPattern parsed;
  std::string_view name = pattern;
  if (pattern.ends_with("/**")) {
    parsed.match = TopicPattern::Match::descendants;
    name.remove_suffix(3);
  } else if (pattern.ends_with("/*")) {
    parsed.match = TopicPattern::Match::children;
    name.remove_suffix(2);
  }
  if (name.empty() && parsed.match != TopicPattern::Match::exact) return parsed;
  if (const std::string problem = service_name_problem(name); !problem.empty()) {
    throw std::invalid_argument("access rule services '" + std::string(pattern) + "': " + problem +
                                " (a pattern is a service name, optionally followed by /* for "
                                "one more level or /** for any depth)");
  }
  parsed.prefix = name;
  return parsed;
}

std::array<AccessRule, 2> topic_rules_of(const ServiceAccessRule& rule) {
  const TopicPattern services = parse_service_pattern(rule.services);
  const auto carriers = [&](std::string_view prefix) {
    return to_string(TopicPattern{std::string(prefix) + services.prefix, services.match});
  };
  return {AccessRule{carriers(service_request_prefix), rule.call, rule.serve},
          AccessRule{carriers(service_reply_prefix), rule.serve, rule.call}};
}

std::vector<WrittenAccessRule> written_access_rules(const std::vector<AccessRule>& rules) {
  std::vector<WrittenAccessRule> written;
  for (std::size_t i = 0; i < rules.size(); ++i) {
    if (i + 1 < rules.size()) {
      if (std::optional<ServiceAccessRule> service = service_rule_of(rules[i], rules[i + 1])) {
        written.emplace_back(std::move(*service));
        ++i;
        continue;
      }
    }
    written.emplace_back(rules[i]);
  }
  return written;
}

}  // namespace agnocast
