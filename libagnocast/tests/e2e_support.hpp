// Helpers for the in-VM end-to-end tests: child processes, pipes, topics.
#pragma once

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast_test/process.hpp>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "chatter_message.hpp"

namespace e2e {

using chatter::Message;
using namespace std::chrono_literals;

// A topic no other test (or earlier run) uses.
inline std::string unique_topic(const std::string& name) {
  static int counter = 0;
  return "/e2e/" + name + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
}

// One-way byte channel between a parent and a forked child.
class Pipe {
 public:
  Pipe() {
    if (::pipe(fds_) != 0) throw std::runtime_error("pipe");
  }
  ~Pipe() {
    ::close(fds_[0]);
    ::close(fds_[1]);
  }
  void send(char byte = 'x') { [[maybe_unused]] auto n = ::write(fds_[1], &byte, 1); }
  // The byte received, or 0 after timeout / end of file.
  char receive(std::chrono::milliseconds timeout = 60s) {
    pollfd entry{fds_[0], POLLIN, 0};
    if (::poll(&entry, 1, static_cast<int>(timeout.count())) != 1) return 0;
    char byte = 0;
    return ::read(fds_[0], &byte, 1) == 1 ? byte : 0;
  }

 private:
  int fds_[2];
};

using agnocast_test::fork_child;

// The child's wait status; kills it after timeout.
inline int wait_child(pid_t pid, std::chrono::seconds timeout = 120s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return status;
    }
    std::this_thread::sleep_for(5ms);
  }
  return status;
}

inline bool exited_ok(int status) { return WIFEXITED(status) && WEXITSTATUS(status) == 0; }

// Spins until predicate holds or timeout passes; returns the predicate.
template <class Predicate>
bool spin_until(agnocast::Executor& executor, Predicate predicate,
                std::chrono::milliseconds timeout = 30s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!predicate()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    executor.spin_once(50ms);
  }
  return true;
}

// Spins until nothing arrives for quiet.
inline void spin_until_quiet(agnocast::Executor& executor,
                             std::chrono::milliseconds quiet = 300ms) {
  while (executor.spin_once(quiet)) {
  }
}

// What a subscription has received: sequence numbers in arrival order, and
// whether every payload verified.
struct Received {
  std::vector<std::uint64_t> seqs;
  bool intact = true;

  // A subscription callback that records into *this (which must outlive it).
  auto recorder() {
    return [this](const agnocast::ipc_shared_ptr<const Message>& message) {
      intact = intact && chatter::verify(*message);
      seqs.push_back(message->seq);
    };
  }
};

inline void publish(agnocast::Publisher<Message>& publisher, std::uint64_t seq,
                    std::size_t size = 64) {
  auto message = publisher.borrow_loaned_message();
  chatter::fill(*message, seq, size);
  publisher.publish(std::move(message));
}

}  // namespace e2e
