// Loading, checking and unloading agnocast.ko.
#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "agnocast/version.hpp"
#include "config.hpp"

namespace agnocastd {

class ModuleError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// True when agnocast.ko is in the kernel (/sys/module/agnocast or the device).
bool module_present();

// "a=1 b=2", the parameter string insmod and modprobe take.
std::string module_parameter_string(const std::map<std::string, std::string>& parameters);

// insmod of path (finit_module) when given, else `modprobe agnocast`;
// throws ModuleError saying what failed, StopRequested on SIGTERM/SIGINT
// while modprobe runs.
void load_module(const std::optional<std::string>& path,
                 const std::map<std::string, std::string>& parameters);

// Waits for /dev/agnocast; false after timeout. Throws StopRequested on
// SIGTERM/SIGINT meanwhile.
bool wait_for_device(std::chrono::milliseconds timeout);

// Empty when this daemon can work with the module, else the reason.
std::string version_problem(const agnocast::Version& module,
                            const agnocast::Version& daemon = agnocast::library_version);

// chgrp/chmod of /dev/agnocast as configured; throws ModuleError.
void apply_device_permissions(const Config::Device& device);

enum class UnloadResult { unloaded, busy, failed };
// rmmod agnocast, never waiting for users to leave.
UnloadResult unload_module();

}  // namespace agnocastd
