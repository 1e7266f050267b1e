#include "iceoryx_runner.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <thread>
#include <vector>

namespace agnocast::bench {
namespace {

std::optional<std::string> find_in_path(const std::string& program) {
  const char* path = getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    std::size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    std::filesystem::path candidate =
        std::filesystem::path(dirs.substr(start, end - start)) / program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return std::nullopt;
}

pid_t exec_child(const std::vector<std::string>& argv, bool quiet) {
  pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    if (quiet) {
      freopen("/dev/null", "w", stdout);
      freopen("/dev/null", "w", stderr);
    }
    std::vector<char*> args;
    for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  return child;
}

bool wait_ok(pid_t child) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

std::optional<IceoryxRunner> IceoryxRunner::start(const std::string& role_program) {
  auto roudi = find_in_path("iox-roudi");
  if (!roudi || access(role_program.c_str(), X_OK) != 0) return std::nullopt;
  pid_t pid = exec_child({*roudi}, true);
  // RouDi needs a moment to create its shared memory before clients connect.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  return IceoryxRunner(role_program, pid);
}

IceoryxRunner::IceoryxRunner(IceoryxRunner&& other) noexcept
    : role_program_(std::move(other.role_program_)), roudi_pid_(other.roudi_pid_) {
  other.roudi_pid_ = -1;
}

IceoryxRunner::~IceoryxRunner() {
  if (roudi_pid_ > 0) {
    kill(roudi_pid_, SIGTERM);
    wait_ok(roudi_pid_);
  }
}

std::vector<std::int64_t> IceoryxRunner::measure(std::size_t size, std::size_t count) {
  constexpr std::size_t warmup = 3;
  Pipe ready = Pipe::open(), ack = Pipe::open(), results = Pipe::open();
  auto fd = [](int value) { return std::to_string(value); };
  const std::string size_text = std::to_string(size), count_text = std::to_string(count + warmup);
  pid_t subscriber = exec_child(
      {role_program_, "sub", "--size", size_text, "--count", count_text, "--ready-fd",
       fd(ready.write_fd), "--ack-fd", fd(ack.write_fd), "--results-fd", fd(results.write_fd)},
      false);
  pid_t publisher = exec_child({role_program_, "pub", "--size", size_text, "--count", count_text,
                                "--ready-fd", fd(ready.read_fd), "--ack-fd", fd(ack.read_fd)},
                               false);
  results.close_write();
  std::vector<std::int64_t> latencies = receive_latencies(results.read_fd);
  bool ok = wait_ok(publisher) & wait_ok(subscriber);
  if (!ok || latencies.size() != count + warmup) {
    throw std::runtime_error("iceoryx benchmark roles failed");
  }
  for (std::int64_t latency : latencies) {
    if (latency < 0) throw std::runtime_error("iceoryx: a payload arrived corrupted");
  }
  latencies.erase(latencies.begin(), latencies.begin() + warmup);
  return latencies;
}

}  // namespace agnocast::bench
