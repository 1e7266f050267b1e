// The POSIX mqueue side agnocast needs: the filesystem mounted at
// /dev/mqueue (the daemon lists queues there) and the configured limits.
#pragma once

#include <string>

#include "config.hpp"

namespace agnocastd {

// Mounts the mqueue filesystem at /dev/mqueue unless it is there; throws
// std::system_error.
void ensure_mqueue_mounted();

// Writes each configured limit to /proc/sys/fs/mqueue/<name>; throws
// std::system_error naming the limit.
void apply_mqueue_limits(const Config::Mqueue& limits);

}  // namespace agnocastd
