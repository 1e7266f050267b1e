#include "instance_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <system_error>

namespace agnocastd {

InstanceLock::InstanceLock(const std::string& path) {
  const std::filesystem::path lock(path);
  if (lock.has_parent_path() && !std::filesystem::exists(lock.parent_path())) {
    std::filesystem::create_directories(lock.parent_path());
    ::chmod(lock.parent_path().c_str(), 0755);
  }
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "cannot open " + path);
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    char buffer[32] = {};
    const ssize_t length = ::pread(fd_, buffer, sizeof(buffer) - 1, 0);
    ::close(fd_);
    if (error != EWOULDBLOCK) {
      throw std::system_error(error, std::generic_category(), "cannot lock " + path);
    }
    std::string pid = length > 0 ? std::string(buffer, static_cast<std::size_t>(length)) : "?";
    while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
    throw AlreadyRunning("agnocastd is already running (pid " + pid + ")");
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 ||
      ::pwrite(fd_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    const int error = errno;
    ::close(fd_);
    throw std::system_error(error, std::generic_category(), "cannot write " + path);
  }
}

InstanceLock::~InstanceLock() { ::close(fd_); }

}  // namespace agnocastd
