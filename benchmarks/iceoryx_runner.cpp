#include "iceoryx_runner.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
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

// Chunk payload sizes cover a header and every payload of the size series;
// few large chunks, since one message is in flight at a time.
constexpr const char* roudi_config = R"([general]
version = 1

[[segment]]

[[segment.mempool]]
size = 1024
count = 512

[[segment.mempool]]
size = 8192
count = 32

[[segment.mempool]]
size = 1049600
count = 4

[[segment.mempool]]
size = 4198400
count = 16

[[segment.mempool]]
size = 16778240
count = 3

[[segment.mempool]]
size = 67109888
count = 2
)";

}  // namespace

std::optional<IceoryxRunner> IceoryxRunner::start(const std::string& role_program) {
  auto roudi = find_in_path("iox-roudi");
  if (!roudi || access(role_program.c_str(), X_OK) != 0) return std::nullopt;
  const std::string config = "/tmp/agnocast-bench-roudi-" + std::to_string(getpid()) + ".toml";
  std::ofstream(config) << roudi_config;
  pid_t pid = exec_child({*roudi, "-c", config}, true);
  // RouDi needs a moment to create its shared memory before clients connect.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  return IceoryxRunner(role_program, pid);
}

IceoryxRunner::IceoryxRunner(IceoryxRunner&& other) noexcept
    : role_program_(std::move(other.role_program_)),
      roudi_pid_(other.roudi_pid_),
      pairs_(other.pairs_) {
  other.roudi_pid_ = -1;
}

IceoryxRunner::~IceoryxRunner() {
  if (roudi_pid_ > 0) {
    kill(roudi_pid_, SIGTERM);
    wait_ok(roudi_pid_);
  }
}

std::vector<std::int64_t> IceoryxRunner::measure(std::size_t size, std::size_t count,
                                                 std::size_t scratch_bytes) {
  constexpr std::size_t warmup = 3;
  const std::string instance = std::to_string(getpid()) + "_" + std::to_string(++pairs_);
  Pipe ready = Pipe::open(), ack = Pipe::open(), results = Pipe::open();
  auto fd = [](int value) { return std::to_string(value); };
  const std::string size_text = std::to_string(size), count_text = std::to_string(count + warmup);
  pid_t subscriber =
      exec_child({role_program_, "sub", "--instance", instance, "--size", size_text, "--count",
                  count_text, "--ready-fd", fd(ready.write_fd), "--ack-fd", fd(ack.write_fd),
                  "--results-fd", fd(results.write_fd)},
                 false);
  pid_t publisher = exec_child({role_program_, "pub", "--instance", instance, "--size", size_text,
                                "--count", count_text, "--scratch", std::to_string(scratch_bytes),
                                "--ready-fd", fd(ready.read_fd), "--ack-fd", fd(ack.read_fd)},
                               false);
  // Only the roles hold these now, so one that dies ends its peer's wait.
  for (Pipe* pipe : {&ready, &ack}) {
    pipe->close_read();
    pipe->close_write();
  }
  results.close_write();
  std::vector<std::int64_t> latencies = receive_latencies(results.read_fd);
  results.close_read();
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

Throughput IceoryxRunner::throughput(std::size_t size, std::size_t count) {
  Pipe ready = Pipe::open(), ack = Pipe::open(), results = Pipe::open();
  auto fd = [](int value) { return std::to_string(value); };
  const std::string size_text = std::to_string(size), count_text = std::to_string(count);
  const std::string instance = std::to_string(getpid()) + "_" + std::to_string(++pairs_);
  pid_t subscriber =
      exec_child({role_program_, "sub", "--instance", instance, "--throughput", "--size", size_text,
                  "--count", count_text, "--ready-fd", fd(ready.write_fd), "--ack-fd",
                  fd(ack.write_fd), "--results-fd", fd(results.write_fd)},
                 false);
  pid_t publisher = exec_child(
      {role_program_, "pub", "--instance", instance, "--throughput", "--size", size_text, "--count",
       count_text, "--ready-fd", fd(ready.read_fd), "--ack-fd", fd(ack.read_fd)},
      false);
  for (Pipe* pipe : {&ready, &ack}) {
    pipe->close_read();
    pipe->close_write();
  }
  results.close_write();
  std::int64_t numbers[3] = {};
  const bool reported = read_all(results.read_fd, numbers, sizeof numbers);
  results.close_read();
  bool ok = wait_ok(publisher) & wait_ok(subscriber);
  if (!ok || !reported) throw std::runtime_error("iceoryx throughput roles failed");
  return throughput_of(numbers[0], numbers[1], static_cast<std::uint64_t>(numbers[2]), count);
}

CpuPerMessage IceoryxRunner::cpu_per_message(std::size_t count) {
  Pipe ready = Pipe::open(), ack = Pipe::open(), results = Pipe::open();
  auto fd = [](int value) { return std::to_string(value); };
  const std::string count_text = std::to_string(count);
  const std::string instance = std::to_string(getpid()) + "_" + std::to_string(++pairs_);
  pid_t subscriber =
      exec_child({role_program_, "sub", "--instance", instance, "--steady", "--count", count_text,
                  "--ready-fd", fd(ready.write_fd), "--ack-fd", fd(ack.write_fd), "--results-fd",
                  fd(results.write_fd)},
                 false);
  pid_t publisher = exec_child({role_program_, "pub", "--instance", instance, "--steady", "--count",
                                count_text, "--ready-fd", fd(ready.read_fd), "--ack-fd",
                                fd(ack.read_fd), "--results-fd", fd(results.write_fd)},
                               false);
  for (Pipe* pipe : {&ready, &ack}) {
    pipe->close_read();
    pipe->close_write();
  }
  results.close_write();
  // Each side sends {side, CPU ns}: 0 the publisher, 1 the subscriber.
  std::int64_t cpu_ns[2] = {-1, -1};
  for (int side = 0; side < 2; ++side) {
    std::int64_t report[2];
    if (!read_all(results.read_fd, report, sizeof report) || report[0] < 0 || report[0] > 1) break;
    cpu_ns[report[0]] = report[1];
  }
  results.close_read();
  bool ok = wait_ok(publisher) & wait_ok(subscriber);
  if (!ok || cpu_ns[0] < 0 || cpu_ns[1] < 0) {
    throw std::runtime_error("iceoryx fixed-rate roles failed");
  }
  return per_message(cpu_ns[0], cpu_ns[1], count);
}

}  // namespace agnocast::bench
