#pragma once

#include <memory>

#include "agnocast/callback_group.hpp"

namespace agnocast {

// Per-subscription settings besides the QoS.
struct SubscriptionOptions {
  // Skip messages published by this process. The kernel filters them, so they
  // never take the subscription's depth nor wake it.
  bool ignore_local_publications = false;
  // Whose callbacks may run at the same time as this one's
  // (MultiThreadedExecutor); empty: the node's default group.
  std::shared_ptr<CallbackGroup> callback_group;
};

}  // namespace agnocast
