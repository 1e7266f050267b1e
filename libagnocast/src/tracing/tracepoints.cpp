// The tracepoints' call sites of libagnocast, and the loading of their
// probes. The probes live in libagnocast_lttng.so (provider.cpp), beside this
// library, which links LTTng-UST; libagnocast itself does not. Loaded, LTTng-UST
// starts two threads of its own, and a process with more than one thread
// takes glibc's multi-threaded paths on every mutex and cancellable system
// call (in callgrind, 530 instructions more per message of a two-hop
// pipeline; 1.4 % of the one-way latency in icount). So the probes are loaded
// only into a process something may trace: when, as it starts, a session
// daemon listens for applications (the system's, or this user's), or
// AGNOCAST_LTTNG=1 asks for them; AGNOCAST_LTTNG=0 never loads them. Without
// the probes each event costs one load and one branch (0.5 % one way in icount).
#define LTTNG_UST_TRACEPOINT_DEFINE
#define LTTNG_UST_TRACEPOINT_PROBE_DYNAMIC_LINKAGE
#include "tracing/tracepoints.h"

#include <dirent.h>
#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "tracing/init_events.hpp"

namespace agnocast::detail {
namespace {

bool has_application_socket(const std::string& folder) {
  DIR* dir = ::opendir(folder.c_str());
  if (!dir) return false;
  bool found = false;
  while (const dirent* entry = ::readdir(dir)) {
    found = found || std::strncmp(entry->d_name, "lttng-ust-sock-", 15) == 0;
  }
  ::closedir(dir);
  return found;
}

bool session_daemon_listening() {
  if (has_application_socket("/var/run/lttng")) return true;
  const char* home = ::secure_getenv("LTTNG_HOME");
  if (!home) home = ::secure_getenv("HOME");
  return home && has_application_socket(std::string(home) + "/.lttng");
}

bool load_probes() {
  // secure_getenv: a set-user-ID program takes no say from its caller.
  const char* asked = ::secure_getenv("AGNOCAST_LTTNG");
  const std::string_view wanted = asked ? asked : "";
  if (wanted == "0" || (wanted != "1" && !session_daemon_listening())) return false;
  std::string path = AGNOCAST_LTTNG_PROVIDER;
  Dl_info self{};
  if (::dladdr(reinterpret_cast<void*>(&load_probes), &self) && self.dli_fname) {
    const std::string library = self.dli_fname;
    const std::string beside = library.substr(0, library.rfind('/') + 1) + AGNOCAST_LTTNG_PROVIDER;
    if (library.find('/') != std::string::npos && ::access(beside.c_str(), R_OK) == 0) {
      path = beside;
    }
  }
  // Not found (a library built without its probes installed): the events stay off.
  return ::dlopen(path.c_str(), RTLD_NOW) != nullptr;
}

// At the process's start, before anything could be traced.
[[maybe_unused]] const bool loaded_at_start = probes_loaded();

}  // namespace

bool probes_loaded() {
  static const bool loaded = load_probes();
  return loaded;
}

}  // namespace agnocast::detail
