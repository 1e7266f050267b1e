// What agnocastd has removed since it started (shown by agnocast-cli daemon status).
#pragma once

#include "agnocast/status.hpp"

namespace agnocastd {

using Counters = agnocast::DaemonCounters;

}  // namespace agnocastd
