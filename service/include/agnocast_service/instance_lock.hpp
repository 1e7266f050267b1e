// One instance of a daemon at a time: an exclusive flock on a lock file,
// which also holds the owner's pid for the message the next instance prints.
//
//   const agnocast_service::InstanceLock lock("/run/agnocast/x.lock", "x");
//   // throws AlreadyRunning("x is already running (pid 42)") while another holds it
#pragma once

#include <stdexcept>
#include <string>

namespace agnocast_service {

class AlreadyRunning : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InstanceLock {
 public:
  // Creates the file's folder (0755) and the file (0644) when missing. Throws
  // AlreadyRunning ("<program> is already running (pid N)") while another
  // process holds the lock, std::system_error when it cannot take it. The
  // lock is released when this object is destroyed or the process ends.
  InstanceLock(const std::string& path, const std::string& program);
  ~InstanceLock();
  InstanceLock(const InstanceLock&) = delete;
  InstanceLock& operator=(const InstanceLock&) = delete;

 private:
  int fd_;
};

}  // namespace agnocast_service
