// Only one agnocastd at a time: an exclusive flock on the lock file, which
// also holds the owner's pid for the message the next instance prints.
#pragma once

#include <stdexcept>
#include <string>

namespace agnocastd {

class AlreadyRunning : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InstanceLock {
 public:
  // Throws AlreadyRunning ("agnocastd is already running (pid N)") or
  // std::system_error.
  explicit InstanceLock(const std::string& path);
  ~InstanceLock();
  InstanceLock(const InstanceLock&) = delete;
  InstanceLock& operator=(const InstanceLock&) = delete;

 private:
  int fd_;
};

}  // namespace agnocastd
