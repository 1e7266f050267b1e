// Umbrella header: everything an agnocast program needs.
#pragma once

#include "agnocast/allocator.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/executor.hpp"
#include "agnocast/ipc_shared_ptr.hpp"
#include "agnocast/message.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/node.hpp"
#include "agnocast/publisher.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/signals.hpp"
#include "agnocast/subscription.hpp"
#include "agnocast/version.hpp"
