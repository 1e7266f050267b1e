// The principals of the config's `access` rules: "user:NAME", "group:NAME",
// their numeric forms "user:1000" and "group:1000", and "*" for anyone.
#pragma once

#include <string_view>

#include "agnocast/access_policy.hpp"

namespace agnocastd {

// Resolves names with the passwd and group databases now (the kernel checks
// ids). Throws std::invalid_argument saying what is wrong, e.g.
// "no group named 'safty'".
agnocast::AccessPrincipal parse_access_principal(std::string_view text);

}  // namespace agnocastd
