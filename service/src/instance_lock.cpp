#include "agnocast_service/instance_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "agnocast_service/atomic_file.hpp"

namespace agnocast_service {

InstanceLock::InstanceLock(const std::string& path, const std::string& program) {
  create_parent_directory(path);
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
    throw AlreadyRunning(program + " is already running (pid " + pid + ")");
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

}  // namespace agnocast_service
