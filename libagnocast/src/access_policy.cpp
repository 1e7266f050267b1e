#include "agnocast/access_policy.hpp"

#include "kernel/device.hpp"

namespace agnocast {

std::optional<AccessPolicy> access_policy() { return detail::Device::open().get_policy(); }

void set_access_policy(const std::optional<AccessPolicy>& policy) {
  detail::Device::open().set_policy(policy);
}

}  // namespace agnocast
