// The exception types the library throws, so callers can tell causes apart.
#pragma once

#include <new>
#include <stdexcept>
#include <string>

namespace agnocast {

// Base of every agnocast runtime failure that is not a bad argument or exhaustion.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// /dev/agnocast does not exist: the kernel module is not loaded.
class ModuleNotLoaded : public Error {
 public:
  ModuleNotLoaded();
};

// The loaded module speaks another major.minor than this library.
class VersionMismatch : public Error {
 public:
  using Error::Error;
};

// The device rejected a request; code() is the errno the kernel returned.
class DeviceError : public Error {
 public:
  DeviceError(int code, const std::string& message) : Error(message), code_(code) {}
  int code() const noexcept { return code_; }

 private:
  int code_;
};

// The topic access policy (agnocastd's "access" rules) refuses this endpoint;
// what() names the topic and how to get access.
class AccessDenied : public DeviceError {
 public:
  explicit AccessDenied(const std::string& message);
};

// The topic carries another message type (name or layout hash) than this
// endpoint; what() names the topic and both types.
class TypeMismatch : public DeviceError {
 public:
  explicit TypeMismatch(const std::string& message);
};

// A POSIX message queue could not be created or opened (often a system limit).
class QueueError : public Error {
 public:
  QueueError(int code, const std::string& message) : Error(message), code_(code) {}
  int code() const noexcept { return code_; }

 private:
  int code_;
};

// create_service() of a name that has a server already; what() names the
// service and the serving process.
class ServiceExists : public Error {
 public:
  using Error::Error;
};

// A request will not be answered: no server was there, or it went away (its
// process died, or its Service was destroyed) with the request pending, or
// the server said it cannot answer it (Service::fail_request).
class ServiceUnavailable : public Error {
 public:
  using Error::Error;
};

// The server's request queue was full: the request was not delivered.
class RequestRejected : public Error {
 public:
  using Error::Error;
};

// async_send_request() over the client's in-flight bound (its QoS depth):
// nothing was sent. Wait for answers, or prune_pending_requests().
class TooManyRequests : public Error {
 public:
  using Error::Error;
};

// The process's shared-memory pool has no room left even after reclaiming.
class PoolExhausted : public std::bad_alloc {
 public:
  explicit PoolExhausted(std::string message) : message_(std::move(message)) {}
  const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

}  // namespace agnocast
