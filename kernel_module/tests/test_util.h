// Helpers shared by the module's in-VM tests: they speak the UAPI directly.
#pragma once

#include <agnocast.h>
#include <agnocast_test/process.hpp>
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace agnocast_test {

inline constexpr gid_t kAgnocastGroup = vm_agnocast_gid;  // the VM's group agnocast, given the device
inline constexpr uid_t kNobody = 65534;

inline constexpr uint8_t kPoison = 0xA5;

template <class T>
T poisoned()
{
  T value;
  std::memset(&value, kPoison, sizeof(value));
  return value;
}

// Poisoned but for flags and reserved (or REGISTER_PROCESS's wake_fd),
// which a request must leave zero.
template <class T>
T poisoned_request()
{
  T value = poisoned<T>();
  value.flags = 0;
  if constexpr (requires { value.reserved; })
    value.reserved = 0;
  else
    value.wake_fd = 0;
  return value;
}

inline int open_device(int flags = O_RDWR)
{
  return ::open(AGNOCAST_DEVICE_PATH, flags | O_CLOEXEC);
}

// Where the loaded module puts slot 0 (its pool_base parameter), or 0.
inline uint64_t module_pool_base()
{
  std::ifstream in("/sys/module/agnocast/parameters/pool_base");
  uint64_t base = 0;
  in >> base;
  return base;
}

// ioctl returning 0 or -errno.
template <class T>
int ioc(int fd, unsigned long cmd, T *arg)
{
  return ::ioctl(fd, cmd, arg) == 0 ? 0 : -errno;
}
inline int ioc0(int fd, unsigned long cmd) { return ::ioctl(fd, cmd, 0) == 0 ? 0 : -errno; }

inline uint64_t uptr(const void *p) { return reinterpret_cast<uint64_t>(p); }

// A registration with an attached, writable pool mapped at its address.
struct Registration {
  int dev = -1;
  int memfd = -1;
  uint64_t addr = 0;
  uint64_t size = 0;
  void *map = nullptr;

  // Step one only: reserve the slot.
  int reserve(int device)
  {
    dev = device;
    agnocast_register_process reg = poisoned_request<agnocast_register_process>();
    reg.pool_fd = -1;
    int ret = ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &reg);
    if (ret) return ret;
    addr = reg.pool_addr;
    size = reg.pool_size;
    return 0;
  }

  // Step two: map a memfd writable, seal it with @seals and attach it.
  int attach(unsigned int seals = AGNOCAST_POOL_SEALS)
  {
    memfd = memfd_create("agnocast-test", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (memfd < 0 || ftruncate(memfd, static_cast<off_t>(size))) return -errno;
    map = mmap(reinterpret_cast<void *>(addr), size, PROT_READ | PROT_WRITE,
               MAP_SHARED | MAP_FIXED_NOREPLACE, memfd, 0);
    if (map == MAP_FAILED) {
      map = nullptr;
      return -errno;
    }
    if (seals && fcntl(memfd, F_ADD_SEALS, seals)) return -errno;
    // As libagnocast does: nobody but root may reopen it read-write.
    if (fchmod(memfd, 0444)) return -errno;
    agnocast_register_process reg = poisoned_request<agnocast_register_process>();
    reg.pool_fd = memfd;
    return ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &reg);
  }

  int full(int device)
  {
    int ret = reserve(device);
    return ret ? ret : attach();
  }

  // Unregisters and unmaps.
  void drop()
  {
    if (dev >= 0) ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS);
    if (map) munmap(map, size);
    if (memfd >= 0) close(memfd);
    map = nullptr;
    memfd = -1;
    dev = -1;
  }
};

inline agnocast_add_endpoint endpoint(const std::string &topic, uint32_t depth,
                                      uint32_t flags = 0, const std::string &node = "node")
{
  agnocast_add_endpoint ep = poisoned<agnocast_add_endpoint>();
  std::memset(ep.topic, 0, sizeof(ep.topic));
  std::memset(ep.node, 0, sizeof(ep.node));
  std::memset(ep.type_name, 0, sizeof(ep.type_name));
  ep.type_hash = 0;
  ep.schema = 0;
  ep.schema_size = 0;
  ep.reserved = 0;
  std::strncpy(ep.topic, topic.c_str(), sizeof(ep.topic) - 1);
  std::strncpy(ep.node, node.c_str(), sizeof(ep.node) - 1);
  ep.depth = depth;
  ep.flags = flags;
  return ep;
}

struct Endpoint {
  uint32_t handle = 0;
  uint32_t id = 0;
};

inline int add_publisher(int dev, const std::string &topic, uint32_t depth, Endpoint *out,
                         uint32_t flags = 0)
{
  agnocast_add_endpoint ep = endpoint(topic, depth, flags);
  int ret = ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep);
  if (!ret) *out = {ep.topic_handle, ep.id};
  return ret;
}

inline int add_subscriber(int dev, const std::string &topic, uint32_t depth, Endpoint *out,
                          uint32_t flags = 0)
{
  agnocast_add_endpoint ep = endpoint(topic, depth, flags);
  int ret = ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep);
  if (!ret) *out = {ep.topic_handle, ep.id};
  return ret;
}

struct PublishResult {
  uint64_t entry_id = 0;
  std::vector<uint32_t> wake;
  std::vector<uint64_t> reclaim;
  uint32_t reclaim_pending = 0;
};

// flags/to_subscriber: AGNOCAST_PUBLISH_TO_ONE, AGNOCAST_PUBLISH_NO_DROP.
inline int publish(int dev, Endpoint pub, uint64_t addr, PublishResult *res = nullptr,
                   uint32_t reclaim_capacity = 64, uint32_t flags = 0, uint32_t to_subscriber = 0)
{
  std::vector<uint32_t> wake(AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX, 0xA5A5A5A5u);
  std::vector<uint64_t> reclaim(reclaim_capacity + 1, 0xA5A5A5A5A5A5A5A5ull);
  agnocast_publish arg = poisoned<agnocast_publish>();
  arg.topic_handle = pub.handle;
  arg.publisher_id = pub.id;
  arg.addr = addr;
  arg.bytes = 8;
  arg.wake_ids = uptr(wake.data());
  arg.wake_capacity = static_cast<uint32_t>(wake.size());
  arg.reclaim = uptr(reclaim.data());
  arg.reclaim_capacity = reclaim_capacity;
  arg.flags = flags;
  arg.to_subscriber = to_subscriber;
  arg.reserved = 0;
  int ret = ioc(dev, AGNOCAST_IOC_PUBLISH, &arg);
  if (!ret && res) {
    res->entry_id = arg.entry_id;
    res->wake.assign(wake.begin(), wake.begin() + arg.wake_count);
    res->reclaim.assign(reclaim.begin(), reclaim.begin() + arg.reclaim_count);
    res->reclaim_pending = arg.reclaim_pending;
  }
  return ret;
}

struct ReceiveResult {
  std::vector<agnocast_entry> entries;
  std::vector<agnocast_pool> pools;
  uint32_t remaining = 0;
};

inline int receive(int dev, Endpoint sub, ReceiveResult *res, uint32_t entry_capacity = 64,
                   uint32_t pool_capacity = 16)
{
  std::vector<agnocast_entry> entries(entry_capacity);
  std::vector<agnocast_pool> pools(pool_capacity);
  // An empty vector's data() may be null, which memset may not be given.
  if (!entries.empty()) std::memset(entries.data(), kPoison, entries.size() * sizeof(entries[0]));
  if (!pools.empty()) std::memset(pools.data(), kPoison, pools.size() * sizeof(pools[0]));
  agnocast_receive arg = poisoned<agnocast_receive>();
  arg.topic_handle = sub.handle;
  arg.subscriber_id = sub.id;
  arg.entries = uptr(entries.data());
  arg.pools = uptr(pools.data());
  arg.entry_capacity = entry_capacity;
  arg.pool_capacity = pool_capacity;
  arg.release_count = 0;
  int ret = ioc(dev, AGNOCAST_IOC_RECEIVE, &arg);
  if (!ret) {
    res->entries.assign(entries.begin(), entries.begin() + arg.entry_count);
    res->pools.assign(pools.begin(), pools.begin() + arg.pool_count);
    res->remaining = arg.remaining;
  }
  return ret;
}

inline int release_list(int dev, Endpoint sub, const std::vector<uint64_t> &entry_ids)
{
  agnocast_release arg{sub.handle, sub.id, uptr(entry_ids.data()),
                       static_cast<uint32_t>(entry_ids.size()), 0};
  return ioc(dev, AGNOCAST_IOC_RELEASE, &arg);
}

inline int release(int dev, Endpoint sub, uint64_t entry_id)
{
  return release_list(dev, sub, {entry_id});
}

inline int topic_info(int dev, const std::string &name, agnocast_topic_info *info,
                      std::vector<agnocast_publisher_info> *pubs = nullptr,
                      std::vector<agnocast_subscriber_info> *subs = nullptr)
{
  std::vector<agnocast_publisher_info> p(64);
  std::vector<agnocast_subscriber_info> s(64);
  *info = poisoned<agnocast_topic_info>();
  std::memset(info->name, 0, sizeof(info->name));
  std::strncpy(info->name, name.c_str(), sizeof(info->name) - 1);
  info->publishers = uptr(p.data());
  info->subscribers = uptr(s.data());
  info->publisher_capacity = 64;
  info->subscriber_capacity = 64;
  int ret = ioc(dev, AGNOCAST_IOC_TOPIC_INFO, info);
  if (!ret && pubs) pubs->assign(p.begin(), p.begin() + std::min(64u, info->publisher_total));
  if (!ret && subs) subs->assign(s.begin(), s.begin() + std::min(64u, info->subscriber_total));
  return ret;
}

inline std::vector<agnocast_process_info> list_processes(int dev)
{
  std::vector<agnocast_process_info> procs(1024);
  agnocast_list_processes arg{uptr(procs.data()), 1024, 0, 0, 0};
  if (ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &arg)) return {};
  procs.resize(std::min(arg.total, 1024u));
  return procs;
}

inline bool process_listed(int dev, pid_t pid)
{
  for (const auto &p : list_processes(dev))
    if (p.pid == pid) return true;
  return false;
}

// Polls cond every 10 ms for up to timeout_ms (teardown runs asynchronously).
inline bool eventually(const std::function<bool()> &cond, int timeout_ms = 10000)
{
  return eventually(cond, std::chrono::milliseconds(timeout_ms), std::chrono::milliseconds(10));
}

// Every exit record waiting now (non-blocking).
inline std::vector<agnocast_exit_record> drain_exit_records(int dev)
{
  std::vector<agnocast_exit_record> out;
  int fd = open_device(O_RDONLY | O_NONBLOCK);
  agnocast_exit_record buf[16];
  for (;;) {
    ssize_t n = read(fd, buf, sizeof(buf));
    if (n <= 0) break;
    out.insert(out.end(), buf, buf + n / sizeof(buf[0]));
  }
  close(fd);
  (void)dev;
  return out;
}

// Policy helpers: one rule with its publish and subscribe principals.
struct Rule {
  std::string prefix;
  uint32_t match;
  std::optional<std::vector<agnocast_principal>> publish, subscribe;
};

inline int set_policy(int dev, const std::vector<Rule>& rules, bool default_deny = false) {
  std::vector<agnocast_policy_rule> raw;
  std::vector<agnocast_principal> principals;
  for (const Rule& rule : rules) {
    agnocast_policy_rule r{};
    std::strncpy(r.prefix, rule.prefix.c_str(), sizeof(r.prefix) - 1);
    r.match = rule.match;
    r.first_principal = static_cast<uint32_t>(principals.size());
    if (rule.publish) {
      r.flags |= AGNOCAST_RULE_PUBLISH;
      r.publish_count = static_cast<uint32_t>(rule.publish->size());
      principals.insert(principals.end(), rule.publish->begin(), rule.publish->end());
    }
    if (rule.subscribe) {
      r.flags |= AGNOCAST_RULE_SUBSCRIBE;
      r.subscribe_count = static_cast<uint32_t>(rule.subscribe->size());
      principals.insert(principals.end(), rule.subscribe->begin(), rule.subscribe->end());
    }
    raw.push_back(r);
  }
  agnocast_policy policy{};
  policy.flags = AGNOCAST_POLICY_PRESENT | (default_deny ? AGNOCAST_POLICY_DEFAULT_DENY : 0);
  policy.rule_count = static_cast<uint32_t>(raw.size());
  policy.rules = uptr(raw.data());
  policy.principal_count = static_cast<uint32_t>(principals.size());
  policy.principals = uptr(principals.data());
  return ioc(dev, AGNOCAST_IOC_SET_POLICY, &policy);
}

inline constexpr agnocast_principal user_principal(uint32_t uid) { return {AGNOCAST_PRINCIPAL_USER, uid}; }
inline constexpr agnocast_principal group_principal(uint32_t gid) { return {AGNOCAST_PRINCIPAL_GROUP, gid}; }
inline constexpr agnocast_principal anyone_principal() { return {AGNOCAST_PRINCIPAL_ANYONE, 0}; }

}  // namespace agnocast_test
