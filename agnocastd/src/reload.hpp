// SIGHUP: the daemon re-reads its whole configuration and applies what can
// change while it runs; a bad file leaves the configuration in force.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "agnocast/access_policy.hpp"
#include "config.hpp"

namespace agnocastd {

// Loads the policy into the kernel (nullopt removes it) and logs what is in
// force. Throws what agnocast::set_access_policy throws.
void apply_access_policy(const std::optional<agnocast::AccessPolicy>& policy);

// One line per key whose new value only a restart would apply (the module
// cannot take new parameters while loaded), naming the old and new values.
std::vector<std::string> restart_only_differences(const Config& in_force, const Config& next);

// Applies next's run-time keys: the access policy, the device permissions,
// the mqueue limits, the log level. On failure, puts in_force's access policy
// back and throws.
void apply_runtime_config(const Config& in_force, const Config& next);

}  // namespace agnocastd
