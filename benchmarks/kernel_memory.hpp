// Kernel memory the module keeps per object, read from the memory cgroup's
// counters: every allocation of the module is charged (GFP_KERNEL_ACCOUNT) to
// the cgroup of the process whose call made it.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>

namespace agnocast::bench {

// Creates `objects` of each kind in a process of a memory cgroup of its own
// (mounting cgroup2 at /sys/fs/cgroup when nothing is there) and reads
// memory.stat's "slab" and "kernel" bytes before and after each kind:
// a topic with its first publisher, a second publisher, a polling
// subscriber, a callback subscriber (with its notification queue), and an
// entry a publisher's depth window keeps. Per kind: bytes per object.
// Throws with the reason when the cgroup cannot be made.
nlohmann::ordered_json measure_kernel_memory(std::size_t objects);

}  // namespace agnocast::bench
