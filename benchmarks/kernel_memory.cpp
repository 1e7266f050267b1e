#include "kernel_memory.hpp"

#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast/limits.hpp>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <std_msgs/msg/u_int64.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.hpp"

namespace agnocast::bench {
namespace {

constexpr char cgroup_root[] = "/sys/fs/cgroup";
// memory.stat's fields, as the kernel names them.
const std::vector<std::string> counted_fields{"slab", "kernel"};

std::string system_error(const std::string& what) { return what + ": " + std::strerror(errno); }

void write_file(const std::string& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
  file.flush();
  if (!file) throw std::runtime_error("cannot write " + text + " to " + path);
}

// The cgroup2 hierarchy, mounted if the system has none, with the memory
// controller given to its children.
void prepare_hierarchy() {
  if (access((std::string(cgroup_root) + "/cgroup.controllers").c_str(), F_OK) != 0 &&
      mount("cgroup2", cgroup_root, "cgroup2", 0, nullptr) != 0) {
    throw std::runtime_error(system_error(std::string("mounting cgroup2 at ") + cgroup_root));
  }
  write_file(std::string(cgroup_root) + "/cgroup.subtree_control", "+memory");
}

// The counted fields of `group`'s memory.stat, after the kernel's periodic
// flush of the per-CPU counters (every 2 s) has surely run.
std::vector<std::int64_t> read_counters(const std::string& group) {
  std::this_thread::sleep_for(std::chrono::milliseconds(2100));
  std::ifstream stat(group + "/memory.stat");
  std::map<std::string, std::int64_t> fields;
  std::string name;
  std::int64_t value = 0;
  while (stat >> name >> value) fields[name] = value;
  std::vector<std::int64_t> counters;
  for (const std::string& field : counted_fields) {
    if (!fields.contains(field)) throw std::runtime_error(group + "/memory.stat has no " + field);
    counters.push_back(fields.at(field));
  }
  return counters;
}

// The child, in `group`: the counters before and after each kind, in
// `kinds` order, written to `fd`.
int create_and_count(const std::string& group, std::size_t objects, int fd) {
  write_file(group + "/cgroup.procs", "0");
  using Message = std_msgs::msg::UInt64;
  agnocast::Node node{"bench_kernel_memory"};
  // What the first endpoint of a process makes once (its record, its pool,
  // the first topic's namespace) is not counted.
  auto warm_publisher = node.create_publisher<Message>("/bench/memory/warm", agnocast::QoS{10});
  auto warm_polling = node.create_polling_subscriber<Message>("/bench/memory/warm", QoS{1});
  auto warm_callback = node.create_subscription<Message>(
      "/bench/memory/warm", QoS{10}, [](const agnocast::ipc_shared_ptr<const Message>&) {});
  warm_publisher->publish(warm_publisher->borrow_loaned_message());
  std::vector<std::int64_t> counters = read_counters(group);
  auto count = [&] {
    const std::vector<std::int64_t> now = read_counters(group);
    counters.insert(counters.end(), now.begin(), now.end());
  };
  auto topic = [](std::size_t i) { return "/bench/memory/topic_" + std::to_string(i); };
  std::vector<std::shared_ptr<agnocast::Publisher<Message>>> first, second;
  for (std::size_t i = 0; i < objects; ++i) {
    first.push_back(node.create_publisher<Message>(topic(i), QoS{10}));
  }
  count();
  for (std::size_t i = 0; i < objects; ++i) {
    second.push_back(node.create_publisher<Message>(topic(i), QoS{10}));
  }
  count();
  std::vector<std::shared_ptr<agnocast::PollingSubscriber<Message>>> polling;
  for (std::size_t i = 0; i < objects; ++i) {
    polling.push_back(node.create_polling_subscriber<Message>(topic(i), QoS{1}));
  }
  count();
  std::vector<std::shared_ptr<agnocast::Subscription<Message>>> callbacks;
  for (std::size_t i = 0; i < objects; ++i) {
    callbacks.push_back(node.create_subscription<Message>(
        topic(i), QoS{10}, [](const agnocast::ipc_shared_ptr<const Message>&) {}));
  }
  count();
  // Entries: a window deep enough to keep every one, nobody subscribed.
  auto keeper = node.create_publisher<Message>("/bench/memory/entries", QoS{qos_depth_max});
  keeper->publish(keeper->borrow_loaned_message());
  const std::vector<std::int64_t> before_entries = read_counters(group);
  for (std::size_t i = 0; i < objects; ++i) keeper->publish(keeper->borrow_loaned_message());
  counters.insert(counters.end(), before_entries.begin(), before_entries.end());
  count();
  write_all(fd, counters.data(), counters.size() * sizeof(std::int64_t));
  return 0;
}

}  // namespace

nlohmann::ordered_json measure_kernel_memory(std::size_t objects) {
  // Four endpoints an object, under the module's default 1,024 a process.
  if (objects == 0 || objects > 250) {
    throw std::invalid_argument("between 1 and 250 objects of each kind");
  }
  prepare_hierarchy();
  const std::string group =
      std::string(cgroup_root) + "/agnocast-bench-memory-" + std::to_string(getpid());
  if (mkdir(group.c_str(), 0755) != 0) throw std::runtime_error(system_error("mkdir " + group));
  Pipe results = Pipe::open();
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error(system_error("fork"));
  if (child == 0) {
    int status = 1;
    try {
      status = create_and_count(group, objects, results.write_fd);
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench: kernel memory: " << error.what() << "\n";
    }
    _exit(status);
  }
  results.close_write();
  // Counters: the start, after each of the four endpoint kinds, before and
  // after the entries.
  constexpr std::size_t snapshots = 7;
  std::vector<std::int64_t> counters(snapshots * counted_fields.size());
  const bool complete =
      read_all(results.read_fd, counters.data(), counters.size() * sizeof(std::int64_t));
  results.close_read();
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  rmdir(group.c_str());
  if (!complete || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("the kernel memory process failed");
  }
  auto at = [&](std::size_t snapshot, std::size_t field) {
    return counters[snapshot * counted_fields.size() + field];
  };
  // Kind, and the snapshots it lies between.
  const std::vector<std::tuple<const char*, std::size_t, std::size_t>> kinds{
      {"topic_with_publisher", 0, 1},
      {"publisher", 1, 2},
      {"polling_subscriber", 2, 3},
      {"callback_subscriber", 3, 4},
      {"held_entry", 5, 6}};
  nlohmann::ordered_json report;
  report["objects"] = objects;
  for (const auto& [kind, from, to] : kinds) {
    for (std::size_t field = 0; field < counted_fields.size(); ++field) {
      report["bytes_per_object"][kind][counted_fields[field]] =
          static_cast<double>(at(to, field) - at(from, field)) / static_cast<double>(objects);
    }
  }
  std::ifstream object_size("/sys/kernel/slab/agnocast_entry/object_size");
  std::size_t entry_size = 0;
  if (object_size >> entry_size) report["entry_object_size"] = entry_size;
  return report;
}

}  // namespace agnocast::bench
