// The agnocast-bridge program: command line, configuration, the relays of
// every configured topic, the status file and systemd's notifications.
// A bridge binary's main() adds its message types to a registry and calls
// run_bridge() (agnocast_add_bridge() in CMake writes that main()).
#pragma once

#include "type_registry.hpp"

namespace agnocast_bridge {

// Exit codes: 0 stopped by SIGINT/SIGTERM (or --check-config passed), 1 a
// runtime failure (DDS domain, agnocast module, another bridge running), 2 a
// bad command line or configuration (the message names the key).
int run_bridge(int argc, char** argv, const TypeRegistry& types);

}  // namespace agnocast_bridge
