#include "mqueue_setup.hpp"

#include <spdlog/spdlog.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <string>
#include <system_error>

#include "agnocast/naming.hpp"
#include "agnocast_service/errno_error.hpp"

namespace agnocastd {

using agnocast_service::throw_errno;

namespace {

constexpr long mqueue_magic = 0x19800202;  // MQUEUE_MAGIC from <linux/magic.h>

void write_limit(const std::string& name, long value) {
  const std::string path = "/proc/sys/fs/mqueue/" + name;
  std::ofstream file(path);
  if (!(file << value << '\n') || !file.flush()) {
    throw_errno("cannot set " + path + " to " + std::to_string(value));
  }
  spdlog::info("set fs.mqueue.{} = {}", name, value);
}

}  // namespace

void ensure_mqueue_mounted() {
  const std::string directory(agnocast::mqueue_directory);
  struct statfs info {};
  if (::statfs(directory.c_str(), &info) == 0 && info.f_type == mqueue_magic) return;
  if (::mkdir(directory.c_str(), 01777) != 0 && errno != EEXIST)
    throw_errno("cannot create " + directory);
  if (::mount("mqueue", directory.c_str(), "mqueue", MS_NOSUID | MS_NODEV | MS_NOEXEC, nullptr) !=
      0) {
    throw_errno("cannot mount the mqueue filesystem at " + directory);
  }
  spdlog::info("mounted the mqueue filesystem at {}", directory);
}

void apply_mqueue_limits(const Config::Mqueue& limits) {
  if (limits.msg_max) write_limit("msg_max", *limits.msg_max);
  if (limits.queues_max) write_limit("queues_max", *limits.queues_max);
  if (limits.msgsize_max) write_limit("msgsize_max", *limits.msgsize_max);
}

}  // namespace agnocastd
