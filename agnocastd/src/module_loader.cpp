#include "module_loader.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>
#include <vector>

#include "agnocast/inspect.hpp"
#include "child_process.hpp"
#include "daemon_signals.hpp"

namespace agnocastd {

namespace {
constexpr const char* module_name = "agnocast";
using agnocast::device_path;
}  // namespace

bool module_present() {
  return ::access(agnocast::module_sysfs_directory, F_OK) == 0 || ::access(device_path, F_OK) == 0;
}

std::string module_parameter_string(const std::map<std::string, std::string>& parameters) {
  std::string joined;
  for (const auto& [name, value] : parameters) {
    if (!joined.empty()) joined += ' ';
    joined += name + "=" + value;
  }
  return joined;
}

namespace {

void insmod(const std::string& path, const std::string& parameters) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw ModuleError("cannot open module " + path + ": " + std::strerror(errno));
  const long result = ::syscall(SYS_finit_module, fd, parameters.c_str(), 0);
  const int error = errno;
  ::close(fd);
  // EEXIST: loaded by someone else meanwhile, which is as good.
  if (result != 0 && error != EEXIST) {
    throw ModuleError("cannot load module " + path + (parameters.empty() ? "" : " " + parameters) +
                      ": " + std::strerror(error) + " (see dmesg)");
  }
}

void modprobe(const std::map<std::string, std::string>& parameters) {
  std::vector<std::string> words{"modprobe", module_name};
  for (const auto& [name, value] : parameters) words.push_back(name + "=" + value);
  bool loaded = false;
  try {
    loaded = run_child_until_stopped(words);
  } catch (const std::system_error& error) {
    throw ModuleError(std::string("cannot run modprobe: ") + error.code().message());
  }
  if (!loaded) {
    throw ModuleError(
        "modprobe agnocast failed: is the module installed (dkms status agnocast)? Or pass "
        "--module PATH to the .ko");
  }
}

}  // namespace

void load_module(const std::optional<std::string>& path,
                 const std::map<std::string, std::string>& parameters) {
  if (path) {
    insmod(*path, module_parameter_string(parameters));
  } else {
    modprobe(parameters);
  }
}

bool wait_for_device(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (::access(device_path, F_OK) != 0) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    if (stop_requested(std::chrono::milliseconds(20))) {
      throw StopRequested("waiting for /dev/agnocast");
    }
  }
  return true;
}

std::string version_problem(const agnocast::Version& module, const agnocast::Version& daemon) {
  if (agnocast::is_compatible(module, daemon)) return {};
  return "agnocast.ko " + module.to_string() + " is incompatible with agnocastd " +
         daemon.to_string() + " (major.minor must match): install the module of this release";
}

void apply_device_permissions(const Config::Device& device) {
  const char* path = device_path;
  if (device.group) {
    const group* entry = ::getgrnam(device.group->c_str());
    if (entry == nullptr) {
      throw ModuleError("config device.group: no group named '" + *device.group +
                        "' (systemd-sysusers creates it from agnocast.conf)");
    }
    if (::chown(path, static_cast<uid_t>(-1), entry->gr_gid) != 0) {
      throw ModuleError(std::string("cannot set the group of ") + path + ": " +
                        std::strerror(errno));
    }
  }
  if (device.mode && ::chmod(path, *device.mode) != 0) {
    throw ModuleError(std::string("cannot set the mode of ") + path + ": " + std::strerror(errno));
  }
}

UnloadResult unload_module() {
  if (::syscall(SYS_delete_module, module_name, O_NONBLOCK) == 0) return UnloadResult::unloaded;
  return errno == EBUSY || errno == EAGAIN ? UnloadResult::busy : UnloadResult::failed;
}

}  // namespace agnocastd
