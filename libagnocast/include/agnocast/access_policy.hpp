// The topic access policy of an IPC namespace: who may publish and subscribe
// which topics. agnocastd loads it into the kernel module, which checks it
// whenever a publisher or subscriber is created (AccessDenied otherwise).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace agnocast {

struct AccessPrincipal {
  enum class Kind { anyone, user, group };
  Kind kind = Kind::anyone;
  std::uint32_t id = 0;  // uid (user) or gid (group); 0 for anyone

  bool operator==(const AccessPrincipal&) const = default;
};

struct AccessRule {
  // An exact topic name, or a name followed by "/*" (exactly one more level)
  // or "/**" (any number of further levels); "/*" and "/**" alone cover the
  // levels below the root.
  std::string topics;
  // Who may publish / subscribe on matching topics. nullopt: the rule says
  // nothing about that direction and the policy's default decides.
  std::optional<std::vector<AccessPrincipal>> publish;
  std::optional<std::vector<AccessPrincipal>> subscribe;

  bool operator==(const AccessRule&) const = default;
};

// The first rule whose pattern matches a topic decides; no match: default_allow.
struct AccessPolicy {
  bool default_allow = true;
  std::vector<AccessRule> rules;

  bool operator==(const AccessPolicy&) const = default;
};

// A topic pattern split into what the kernel matches.
struct TopicPattern {
  enum class Match { exact, children, descendants };
  std::string prefix;  // empty only for "/*" and "/**"
  Match match = Match::exact;
};

// Parses a rule's "topics" pattern; throws std::invalid_argument saying what
// is wrong with it and what is allowed.
TopicPattern parse_topic_pattern(std::string_view pattern);
// The pattern as written in a configuration ("/a/**").
std::string to_string(const TopicPattern& pattern);
// Whether a topic matches, with the kernel's semantics (for tools and tests).
bool matches(const TopicPattern& pattern, std::string_view topic);
// Whether `outer` matches every topic `inner` matches: a rule of pattern
// `inner` after one of pattern `outer` never decides anything.
bool covers(const TopicPattern& outer, const TopicPattern& inner);

// What having no policy means, as the daemon logs it and the CLI shows it.
inline constexpr std::string_view no_access_policy_meaning =
    "no topic access policy: anyone with access to /dev/agnocast may publish and subscribe";

// The policy in force in this process's IPC namespace; nullopt when none.
// Anyone who can open /dev/agnocast may read it.
std::optional<AccessPolicy> access_policy();
// Replaces (or, with nullopt, removes) the policy of this process's IPC
// namespace. Endpoints that exist keep working; new ones follow the new
// policy. Needs CAP_SYS_ADMIN (DeviceError with code EPERM otherwise);
// throws std::invalid_argument for a bad pattern or too many rules.
void set_access_policy(const std::optional<AccessPolicy>& policy);

}  // namespace agnocast
