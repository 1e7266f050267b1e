// What the in-VM C++ tests share (the components' tests and the kernel
// module's): files, child processes run as other users, polling for a
// condition, and the test bed's agnocast group.
#pragma once

#include <fcntl.h>
#include <grp.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace agnocast_test {

// The group "agnocast" of the VM's /etc/group (tests/vm/run-vm-suite).
inline constexpr gid_t vm_agnocast_gid = 990;

// The whole file; empty when it cannot be read.
inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Who a child process becomes: uid, primary gid and supplementary groups.
struct Identity {
  uid_t uid;
  gid_t gid;
  std::vector<gid_t> groups;
};

// Becomes uid with primary group gid and the supplementary groups (in a
// forked child: there is no way back); false when that fails.
inline bool become(uid_t uid, gid_t gid, const std::vector<gid_t>& groups = {}) {
  return ::setgroups(groups.size(), groups.data()) == 0 && ::setgid(gid) == 0 && ::setuid(uid) == 0;
}

// In a forked child: become `who`; exits 126 when that fails.
inline void become(const Identity& who) {
  if (!become(who.uid, who.gid, who.groups)) ::_exit(126);
}

// Runs args[0] from PATH with stdout into `out` and stderr into `err` (the
// same file when they are equal; created before becoming `who`, when
// given); exit status 127 when it cannot be run.
inline pid_t spawn(const std::vector<std::string>& args, const std::string& out,
                   const std::string& err, const Identity* who = nullptr) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd =
        err == out ? out_fd : ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out_fd, STDOUT_FILENO);
    ::dup2(err_fd, STDERR_FILENO);
    if (who) become(*who);
    std::vector<char*> argv;
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// Runs args[0] from PATH with stdout and stderr into `log`.
inline pid_t spawn(const std::vector<std::string>& args, const std::string& log,
                   const Identity* who = nullptr) {
  return spawn(args, log, log, who);
}

// The exit status, or 128 + the signal that ended it.
inline int wait_exit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// How a command ended and what it printed.
struct Outcome {
  int code = -1;  // its exit status; -1 when a signal ended it
  std::string out;
  std::string err;
};

// Runs `command` through /bin/sh (as `who`, when given) with stdout and
// stderr into `stem`.out and `stem`.err, and waits for it.
inline Outcome run_shell(const std::string& command, const std::string& stem,
                         const Identity* who = nullptr) {
  const std::string out = stem + ".out";
  const std::string err = stem + ".err";
  const pid_t pid = spawn({"/bin/sh", "-c", command}, out, err, who);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

// Runs body in a forked child, not waited for: its exit status is what body
// returns, 99 when it throws (after printing why).
inline pid_t fork_child(const std::function<int()>& body) {
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    int code = 98;
    try {
      code = body();
    } catch (const std::exception& error) {
      std::fprintf(stderr, "child %d: %s\n", ::getpid(), error.what());
      code = 99;
    }
    std::fflush(nullptr);
    ::_exit(code);
  }
  return pid;
}

// Runs fn in a forked child, whose exit status is what fn returns; that
// status, or 128 + the signal that ended it.
inline int in_child(const std::function<int()>& fn) {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(fn());
  return wait_exit(pid);
}

// Ends a child that may be stopped (SIGCONT, SIGTERM, reaped); pid becomes -1.
inline void stop(pid_t& pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGCONT);
  ::kill(pid, SIGTERM);
  ::waitpid(pid, nullptr, 0);
  pid = -1;
}

// Polls `condition` every `poll` until it holds (true) or `limit` passed
// (false).
inline bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds limit,
                       std::chrono::milliseconds poll = std::chrono::milliseconds(50)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(poll);
  }
  return true;
}

}  // namespace agnocast_test
