// agnocastd's configuration file, its access policy (topics and services
// rules) included, over any text: a Config or a ConfigError naming the key,
// and what it accepts the library and the kernel take as it is: every
// kernel rule's pattern parses and reads back as written, the policy within
// <agnocast/limits.hpp>, the log level one spdlog knows, the device mode
// permission bits only.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "agnocast/access_policy.hpp"
#include "agnocast/limits.hpp"
#include "config.hpp"

namespace {

void check_policy(const agnocast::AccessPolicy& policy) {
  if (policy.rules.size() > agnocast::access_policy_rules_max) std::abort();
  std::size_t principals = 0;
  for (const agnocast::AccessRule& rule : policy.rules) {
    try {
      if (agnocast::to_string(agnocast::parse_topic_pattern(rule.topics)) != rule.topics) {
        std::abort();
      }
    } catch (const std::invalid_argument&) {
      std::abort();
    }
    for (const auto& list : {rule.publish, rule.subscribe}) {
      if (!list) continue;
      principals += list->size();
      for (const agnocast::AccessPrincipal& principal : *list) {
        // (uid_t)-1 is "no id" to the kernel; anyone carries no id at all.
        if (principal.id == UINT32_MAX) std::abort();
        if (principal.kind == agnocast::AccessPrincipal::Kind::anyone && principal.id != 0) {
          std::abort();
        }
      }
    }
  }
  if (principals > agnocast::access_policy_principals_max) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const agnocastd::Config config = agnocastd::parse_config(text);
    if (config.access) check_policy(*config.access);
    if (!agnocastd::is_log_level(config.log_level)) std::abort();
    if (config.device.mode && *config.device.mode > 0777) std::abort();
  } catch (const agnocastd::ConfigError&) {
  }
  return 0;
}
