// Service rules of the access policy: who may serve and who may call the
// services a pattern names. The kernel knows only topic rules, so a service
// rule stands, in its place in the list, for two topic rules on the topics
// that carry the services (<agnocast/naming.hpp>): a server subscribes to the
// request topic and publishes on the reply topic, a client the other way round.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "agnocast/access_policy.hpp"

namespace agnocast {

struct ServiceAccessRule {
  // A service name, or one followed by "/*" (one more level) or "/**" (any
  // depth); "/*" and "/**" alone cover the services below the root.
  std::string services;
  // Who may serve / call matching services. nullopt: the rule says nothing
  // about that right and the policy's default decides.
  std::optional<std::vector<AccessPrincipal>> serve;
  std::optional<std::vector<AccessPrincipal>> call;

  bool operator==(const ServiceAccessRule&) const = default;
};

// Parses a rule's "services" pattern (prefix empty only for "/*" and "/**");
// throws std::invalid_argument saying what is wrong with it and what is allowed.
TopicPattern parse_service_pattern(std::string_view pattern);

// The two topic rules the kernel enforces for a service rule, in this order:
// on the request topics (call = publish, serve = subscribe), then on the
// reply topics (serve = publish, call = subscribe). The patterns keep their
// kind: "/arm/*" -> "/_service_request/arm/*", "/**" -> "/_service_request/**".
// Throws like parse_service_pattern().
std::array<AccessRule, 2> topic_rules_of(const ServiceAccessRule& rule);

// A policy's rules as people write them: each pair of topic rules that
// topic_rules_of() makes is given back as its service rule, every other rule
// as it is, in the kernel's order.
using WrittenAccessRule = std::variant<AccessRule, ServiceAccessRule>;
std::vector<WrittenAccessRule> written_access_rules(const std::vector<AccessRule>& rules);

}  // namespace agnocast
