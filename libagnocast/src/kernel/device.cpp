#include "kernel/device.hpp"

#include <agnocast.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <utility>

#include "agnocast/access_policy.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/limits.hpp"
#include "log_internal.hpp"

namespace agnocast {

static_assert(std::string_view(device_path) == AGNOCAST_DEVICE_PATH,
              "inspect.hpp's device_path is the UAPI's");

ModuleNotLoaded::ModuleNotLoaded()
    : Error("agnocast kernel module is not loaded (" AGNOCAST_DEVICE_PATH
            " missing): run `systemctl start agnocastd`") {}

AccessDenied::AccessDenied(const std::string& message) : DeviceError(EACCES, message) {}

TypeMismatch::TypeMismatch(const std::string& message) : DeviceError(EPROTOTYPE, message) {}

}  // namespace agnocast

namespace agnocast::detail {
namespace {

static_assert(AGNOCAST_VERSION_MAJOR == library_version.major &&
                  AGNOCAST_VERSION_MINOR == library_version.minor,
              "the UAPI header and the project version must agree on major.minor");
// <agnocast/limits.hpp> mirrors the UAPI's limits: a change on either side
// that the other does not follow stops the build here.
static_assert(AGNOCAST_DEPTH_MAX == qos_depth_max && qos_depth_min == 1);
static_assert(AGNOCAST_TOPIC_NAME_MAX > topic_name_max,
              "the kernel must take every topic name the library allows");
static_assert(sizeof(agnocast_add_endpoint::topic) == AGNOCAST_TOPIC_NAME_MAX);
static_assert(AGNOCAST_NODE_NAME_MAX == node_name_max + 1);
static_assert(sizeof(agnocast_add_endpoint::node) == AGNOCAST_NODE_NAME_MAX);
static_assert(AGNOCAST_TYPE_NAME_MAX == type_name_max + 1);
static_assert(sizeof(agnocast_add_endpoint::type_name) == AGNOCAST_TYPE_NAME_MAX);
static_assert(AGNOCAST_SCHEMA_MAX == schema_max_bytes);
static_assert(AGNOCAST_PUBLISHERS_PER_TOPIC_MAX == publishers_per_topic_max);
static_assert(AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX == subscribers_per_topic_max);
static_assert(Kernel::receive_entries_max == AGNOCAST_RECEIVE_BATCH);
static_assert(AGNOCAST_POLICY_RULES_MAX == access_policy_rules_max);
static_assert(AGNOCAST_POLICY_PRINCIPALS_MAX == access_policy_principals_max);

std::string errno_advice(int err) {
  switch (err) {
    case ESRCH:
      return "this process is not registered with the module";
    case EXDEV:
      return "this process moved to another IPC namespace after it started using agnocast; "
             "create agnocast objects only after unshare/setns";
    case ENOENT:
      return "no such topic, endpoint or entry";
    case EPERM:
      return "the endpoint belongs to another process, or the operation needs CAP_SYS_ADMIN";
    case EINVAL:
      return "the module rejected an argument as invalid";
    case ENOMEM:
      return "the kernel is out of memory";
    case ENOTTY:
      return "the module does not know this command; are the module and library versions equal?";
    case EFAULT:
      return "an address is outside the memory the module accepts";
    case EDQUOT:
      return "this subscriber holds max_held_per_subscriber messages (module parameter): "
             "release some (drop their ipc_shared_ptr) or raise the parameter";
    default:
      return std::strerror(err);
  }
}

[[noreturn]] void fail(std::string_view command, int err, std::string_view detail = {}) {
  std::string message = "agnocast: ";
  message += command;
  message += " failed: ";
  message += detail.empty() ? errno_advice(err) : std::string(detail);
  message += " (";
  message += std::strerror(err);
  message += ")";
  throw DeviceError(err, message);
}

// Retries on EINTR; returns 0 or the errno.
int call(int fd, unsigned long request, void* argument) {
  for (;;) {
    if (::ioctl(fd, request, argument) == 0) return 0;
    if (errno != EINTR) return errno;
  }
}

void copy_name(char* destination, std::size_t capacity, const std::string& source,
               std::string_view what) {
  if (source.size() >= capacity) {
    throw std::invalid_argument(std::string(what) + " is too long: at most " +
                                std::to_string(capacity - 1) + " characters");
  }
  std::memcpy(destination, source.data(), source.size());
  destination[source.size()] = '\0';
}

std::string bounded_string(const char* text, std::size_t capacity) {
  return std::string(text, ::strnlen(text, capacity));
}

agnocast_add_endpoint to_uapi(const EndpointRequest& request) {
  agnocast_add_endpoint argument{};
  copy_name(argument.topic, sizeof argument.topic, request.topic, "topic name");
  copy_name(argument.node, sizeof argument.node, request.node, "node name");
  copy_name(argument.type_name, sizeof argument.type_name, request.type_name, "message type name");
  argument.type_hash = request.type_hash;
  if (request.schema.size() > schema_max_bytes) {
    throw std::invalid_argument("the schema of message type " + request.type_name + " has " +
                                std::to_string(request.schema.size()) + " bytes: at most " +
                                std::to_string(schema_max_bytes));
  }
  argument.schema = reinterpret_cast<std::uintptr_t>(request.schema.data());
  argument.schema_size = static_cast<std::uint32_t>(request.schema.size());
  argument.depth = request.depth;
  argument.flags = (request.transient_local ? AGNOCAST_TRANSIENT_LOCAL : 0U) |
                   (request.polling ? AGNOCAST_POLLING : 0U) |
                   (request.ignore_local ? AGNOCAST_IGNORE_LOCAL : 0U) |
                   (request.wake_once ? AGNOCAST_WAKE_ONCE : 0U);
  return argument;
}

std::string add_endpoint_advice(int err, const EndpointRequest& request, std::string_view kind) {
  switch (err) {
    case ENOSPC:
      return "topic " + request.topic + " already has the maximum number of " + std::string(kind) +
             "s";
    case ENFILE:
      return "the IPC namespace has max_topics_per_namespace topics (module parameter): remove "
             "unused topics or raise the parameter (\"module_parameters\" in "
             "/etc/agnocast/agnocastd.json)";
    case EMFILE:
      return "this process has max_endpoints_per_process publishers and subscribers (module "
             "parameter): remove some or raise the parameter (\"module_parameters\" in "
             "/etc/agnocast/agnocastd.json)";
    case EINVAL:
      return "the module refused topic '" + request.topic + "', node '" + request.node +
             "', message type '" + request.type_name + "' or depth " +
             std::to_string(request.depth) + " (" + std::to_string(qos_depth_min) + ".." +
             std::to_string(qos_depth_max) + ")";
    default:
      return {};
  }
}

std::string layout_hash_hex(std::uint64_t value) {
  char text[19];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

[[noreturn]] void fail_add_endpoint(Device& device, std::string_view command, int err,
                                    const EndpointRequest& request, std::string_view kind) {
  if (err == EPROTOTYPE) {
    std::string topic_type = "another type";
    TopicInfo info;
    try {
      if (device.topic_info(request.topic, info)) {
        topic_type =
            "'" + info.type_name + "' (layout hash " + layout_hash_hex(info.type_hash) + ")";
      }
    } catch (const DeviceError&) {
      // The message below still says what this endpoint wanted.
    }
    throw TypeMismatch("agnocast: " + std::string(command) + " failed: topic " + request.topic +
                       " carries " + topic_type + ", but this " + std::string(kind) + " uses '" +
                       request.type_name + "' (layout hash " + layout_hash_hex(request.type_hash) +
                       "): use the topic's message type, or rebuild both programs against the "
                       "same definition of it");
  }
  if (err == EACCES) {
    throw AccessDenied(
        "agnocast: " + std::string(command) + " failed: the topic access policy does not let " +
        "this process (uid " + std::to_string(::geteuid()) + ") " +
        (kind == "publisher" ? "publish" : "subscribe to") + " topic " + request.topic +
        ": ask the administrator to allow it in the \"access\" rules of "
        "/etc/agnocast/agnocastd.json (`agnocast-cli policy show` shows the policy)");
  }
  fail(command, err, add_endpoint_advice(err, request, kind));
}

std::uint32_t principal_kind(AccessPrincipal::Kind kind) {
  switch (kind) {
    case AccessPrincipal::Kind::user:
      return AGNOCAST_PRINCIPAL_USER;
    case AccessPrincipal::Kind::group:
      return AGNOCAST_PRINCIPAL_GROUP;
    case AccessPrincipal::Kind::anyone:
      break;
  }
  return AGNOCAST_PRINCIPAL_ANYONE;
}

AccessPrincipal::Kind principal_kind(std::uint32_t kind) {
  switch (kind) {
    case AGNOCAST_PRINCIPAL_USER:
      return AccessPrincipal::Kind::user;
    case AGNOCAST_PRINCIPAL_GROUP:
      return AccessPrincipal::Kind::group;
    default:
      return AccessPrincipal::Kind::anyone;
  }
}

std::uint32_t match_kind(TopicPattern::Match match) {
  switch (match) {
    case TopicPattern::Match::children:
      return AGNOCAST_MATCH_CHILDREN;
    case TopicPattern::Match::descendants:
      return AGNOCAST_MATCH_DESCENDANTS;
    case TopicPattern::Match::exact:
      break;
  }
  return AGNOCAST_MATCH_EXACT;
}

TopicPattern::Match match_kind(std::uint32_t match) {
  switch (match) {
    case AGNOCAST_MATCH_CHILDREN:
      return TopicPattern::Match::children;
    case AGNOCAST_MATCH_DESCENDANTS:
      return TopicPattern::Match::descendants;
    default:
      return TopicPattern::Match::exact;
  }
}

}  // namespace

void seal_pool(int memfd) {
  if (::fcntl(memfd, F_ADD_SEALS, AGNOCAST_POOL_SEALS) != 0) {
    const int err = errno;
    throw Error("agnocast: sealing the shared pool (F_ADD_SEALS) failed: " +
                std::string(std::strerror(err)));
  }
  // Seals already forbid writing; the mode also refuses read-write reopening
  // through /proc/<pid>/fd to everyone but root.
  if (::fchmod(memfd, 0444) != 0) {
    const int err = errno;
    throw Error("agnocast: making the shared pool read-only (fchmod) failed: " +
                std::string(std::strerror(err)));
  }
}

Device Device::open(bool nonblocking) {
  const int extra = O_CLOEXEC | (nonblocking ? O_NONBLOCK : 0);
  int fd = ::open(AGNOCAST_DEVICE_PATH, O_RDWR | extra);
  if (fd < 0 && errno == EACCES) fd = ::open(AGNOCAST_DEVICE_PATH, O_RDONLY | extra);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT || err == ENXIO || err == ENODEV) throw ModuleNotLoaded();
    fail("open " AGNOCAST_DEVICE_PATH, err,
         err == EACCES ? "permission denied: only root and members of group agnocast may use "
                         "agnocast; join the group (`sudo usermod -aG agnocast $USER`, then log "
                         "in again)"
                       : std::string_view{});
  }
  return Device(fd);
}

Device::Device(Device&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), wake_fd_(std::exchange(other.wake_fd_, -1)) {}

Device& Device::operator=(Device&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    wake_fd_ = std::exchange(other.wake_fd_, -1);
  }
  return *this;
}

Device::~Device() { close(); }

void Device::close() noexcept {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  if (wake_fd_ >= 0) ::close(std::exchange(wake_fd_, -1));
}

Version Device::get_version() const {
  agnocast_version argument{};
  if (int err = call(fd_, AGNOCAST_IOC_GET_VERSION, &argument)) fail("GET_VERSION", err);
  return Version{argument.major, argument.minor, argument.patch};
}

PoolSlot Device::register_process(int pool_fd) {
  agnocast_register_process argument{};
  argument.pool_fd = pool_fd;
  // The module takes a wake eventfd once: give it with the first step only.
  if (pool_fd == -1 && wake_fd_ < 0) {
    wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (wake_fd_ < 0) fail("eventfd for the module's wake-ups", errno);
    argument.flags = AGNOCAST_REGISTER_WAKE_EVENTFD;
    argument.wake_fd = wake_fd_;
  }
  if (int err = call(fd_, AGNOCAST_IOC_REGISTER_PROCESS, &argument)) {
    // Not taken: the next first step gives a new one.
    if (argument.flags & AGNOCAST_REGISTER_WAKE_EVENTFD) ::close(std::exchange(wake_fd_, -1));
    switch (err) {
      case ENOSPC:
        fail("REGISTER_PROCESS", err,
             "every agnocast pool slot is in use; raise the module parameter pool_count "
             "(modprobe agnocast pool_count=N, or the agnocastd configuration)");
      case EBUSY:
        fail("REGISTER_PROCESS", err, "this process's pool is already attached");
      case EPERM:
        fail("REGISTER_PROCESS", err,
             "the module refused the pool because it is not sealed against writes by others "
             "(library and module versions differ?)");
      default:
        fail("REGISTER_PROCESS", err);
    }
  }
  return PoolSlot{argument.pid, argument.pool_addr, argument.pool_size};
}

void Device::unregister_process() const {
  if (int err = call(fd_, AGNOCAST_IOC_UNREGISTER_PROCESS, nullptr)) {
    fail("UNREGISTER_PROCESS", err);
  }
}

EndpointId Device::add_publisher(const EndpointRequest& request) {
  agnocast_add_endpoint argument = to_uapi(request);
  if (int err = call(fd_, AGNOCAST_IOC_ADD_PUBLISHER, &argument)) {
    fail_add_endpoint(*this, "ADD_PUBLISHER", err, request, "publisher");
  }
  return EndpointId{argument.topic_handle, argument.id};
}

EndpointId Device::add_subscriber(const EndpointRequest& request) {
  agnocast_add_endpoint argument = to_uapi(request);
  if (int err = call(fd_, AGNOCAST_IOC_ADD_SUBSCRIBER, &argument)) {
    fail_add_endpoint(*this, "ADD_SUBSCRIBER", err, request, "subscriber");
  }
  return EndpointId{argument.topic_handle, argument.id};
}

void Device::remove_publisher(EndpointId endpoint) {
  agnocast_remove_endpoint argument{endpoint.topic_handle, endpoint.id};
  if (int err = call(fd_, AGNOCAST_IOC_REMOVE_PUBLISHER, &argument)) {
    fail("REMOVE_PUBLISHER", err);
  }
}

void Device::remove_subscriber(EndpointId endpoint) {
  agnocast_remove_endpoint argument{endpoint.topic_handle, endpoint.id};
  if (int err = call(fd_, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &argument)) {
    fail("REMOVE_SUBSCRIBER", err);
  }
}

void Device::notify_failed(EndpointId publisher, std::uint32_t subscriber_id) noexcept {
  agnocast_notify_failed argument{};
  argument.topic_handle = publisher.topic_handle;
  argument.publisher_id = publisher.id;
  argument.subscriber_id = subscriber_id;
  // ENOENT: the subscriber is gone, and nothing waits for it.
  if (int err = call(fd_, AGNOCAST_IOC_NOTIFY_FAILED, &argument); err && err != ENOENT) {
    log(LogLevel::warning, std::string("agnocast: NOTIFY_FAILED: ") + std::strerror(err));
  }
}

PublishResult Device::publish(EndpointId publisher, std::uint64_t addr, std::uint64_t bytes,
                              std::span<std::uint32_t> wake_ids, std::span<std::uint64_t> reclaim,
                              const ServiceRoute& route) {
  agnocast_publish argument{};
  if (route.to_subscriber) {
    argument.flags |= AGNOCAST_PUBLISH_TO_ONE;
    argument.to_subscriber = *route.to_subscriber;
  }
  if (route.no_drop) argument.flags |= AGNOCAST_PUBLISH_NO_DROP;
  argument.topic_handle = publisher.topic_handle;
  argument.publisher_id = publisher.id;
  argument.addr = addr;
  argument.bytes = bytes;
  argument.wake_ids = reinterpret_cast<std::uintptr_t>(wake_ids.data());
  argument.wake_capacity = static_cast<std::uint32_t>(wake_ids.size());
  argument.reclaim = reinterpret_cast<std::uintptr_t>(reclaim.data());
  argument.reclaim_capacity = static_cast<std::uint32_t>(reclaim.size());
  // ENOBUFS is for the caller to handle (grow wake_ids and retry), so it is thrown plainly.
  if (int err = call(fd_, AGNOCAST_IOC_PUBLISH, &argument)) {
    fail("PUBLISH", err,
         err == ENOBUFS ? "more subscribers than wake-up slots" : std::string_view{});
  }
  return PublishResult{argument.entry_id, argument.wake_count, argument.reclaim_count,
                       argument.reclaim_pending};
}

ReclaimResult Device::reclaim(std::span<std::uint64_t> reclaim) {
  agnocast_reclaim argument{};
  argument.reclaim = reinterpret_cast<std::uintptr_t>(reclaim.data());
  argument.reclaim_capacity = static_cast<std::uint32_t>(reclaim.size());
  if (int err = call(fd_, AGNOCAST_IOC_RECLAIM, &argument)) fail("RECLAIM", err);
  return ReclaimResult{argument.reclaim_count, argument.reclaim_pending};
}

ReceiveResult Device::receive(EndpointId subscriber, std::span<ReceivedEntry> entries,
                              std::span<PoolGrant> pools,
                              std::span<const std::uint64_t> release_ids) {
  // On the stack: this runs for every wake-up.
  std::array<agnocast_entry, receive_entries_max> raw_entries;
  std::array<agnocast_pool, receive_pools_max> raw_pools;
  agnocast_receive argument{};
  argument.topic_handle = subscriber.topic_handle;
  argument.subscriber_id = subscriber.id;
  argument.entries = reinterpret_cast<std::uintptr_t>(raw_entries.data());
  argument.entry_capacity =
      static_cast<std::uint32_t>(std::min(entries.size(), raw_entries.size()));
  argument.pools = reinterpret_cast<std::uintptr_t>(raw_pools.data());
  argument.pool_capacity = static_cast<std::uint32_t>(std::min(pools.size(), raw_pools.size()));
  argument.release_ids = reinterpret_cast<std::uintptr_t>(release_ids.data());
  argument.release_count = static_cast<std::uint32_t>(release_ids.size());
  if (int err = call(fd_, AGNOCAST_IOC_RECEIVE, &argument)) fail("RECEIVE", err);
  for (std::uint32_t i = 0; i < argument.entry_count; ++i) {
    entries[i] =
        ReceivedEntry{raw_entries[i].entry_id, raw_entries[i].addr, raw_entries[i].publisher_id};
  }
  for (std::uint32_t i = 0; i < argument.pool_count; ++i) {
    pools[i] = PoolGrant{raw_pools[i].addr, raw_pools[i].size, raw_pools[i].fd, raw_pools[i].pid};
  }
  return ReceiveResult{argument.entry_count, argument.pool_count, argument.remaining};
}

TakeResult Device::take(EndpointId subscriber) {
  agnocast_take argument{};
  argument.topic_handle = subscriber.topic_handle;
  argument.subscriber_id = subscriber.id;
  if (int err = call(fd_, AGNOCAST_IOC_TAKE, &argument)) fail("TAKE", err);
  TakeResult result;
  result.has_entry = argument.entry_count == 1;
  result.entry =
      ReceivedEntry{argument.entry.entry_id, argument.entry.addr, argument.entry.publisher_id};
  result.has_pool = argument.pool_count == 1;
  if (result.has_pool) {
    result.pool =
        PoolGrant{argument.pool.addr, argument.pool.size, argument.pool.fd, argument.pool.pid};
  }
  return result;
}

void Device::release(EndpointId subscriber, std::span<const std::uint64_t> entry_ids) {
  agnocast_release argument{};
  argument.topic_handle = subscriber.topic_handle;
  argument.subscriber_id = subscriber.id;
  argument.entry_ids = reinterpret_cast<std::uintptr_t>(entry_ids.data());
  argument.count = static_cast<std::uint32_t>(entry_ids.size());
  if (int err = call(fd_, AGNOCAST_IOC_RELEASE, &argument)) fail("RELEASE", err);
}

std::uint32_t Device::shed() {
  agnocast_shed argument{};
  if (int err = call(fd_, AGNOCAST_IOC_SHED, &argument)) fail("SHED", err);
  return argument.shed;
}

std::optional<AccessPolicy> Device::get_policy() const {
  std::vector<agnocast_policy_rule> rules;
  std::vector<agnocast_principal> principals;
  agnocast_policy argument{};
  for (;;) {
    argument = {};
    argument.rules = reinterpret_cast<std::uintptr_t>(rules.data());
    argument.rule_count = static_cast<std::uint32_t>(rules.size());
    argument.principals = reinterpret_cast<std::uintptr_t>(principals.data());
    argument.principal_count = static_cast<std::uint32_t>(principals.size());
    const int err = call(fd_, AGNOCAST_IOC_GET_POLICY, &argument);
    if (err == 0) break;
    if (err != ENOSPC) fail("GET_POLICY", err);
    // The policy changed size: fetch again with the totals just reported.
    rules.resize(argument.rule_count);
    principals.resize(argument.principal_count);
  }
  if (!(argument.flags & AGNOCAST_POLICY_PRESENT)) return std::nullopt;
  AccessPolicy policy;
  policy.default_allow = !(argument.flags & AGNOCAST_POLICY_DEFAULT_DENY);
  const auto principal_range = [&](std::uint32_t first, std::uint32_t count) {
    std::vector<AccessPrincipal> out;
    for (std::uint32_t i = first; i < first + count && i < argument.principal_count; ++i) {
      out.push_back({principal_kind(principals[i].kind), principals[i].id});
    }
    return out;
  };
  for (std::uint32_t i = 0; i < argument.rule_count; ++i) {
    const agnocast_policy_rule& raw = rules[i];
    AccessRule rule;
    rule.topics = to_string(
        TopicPattern{bounded_string(raw.prefix, sizeof raw.prefix), match_kind(raw.match)});
    if (raw.flags & AGNOCAST_RULE_PUBLISH) {
      rule.publish = principal_range(raw.first_principal, raw.publish_count);
    }
    if (raw.flags & AGNOCAST_RULE_SUBSCRIBE) {
      rule.subscribe =
          principal_range(raw.first_principal + raw.publish_count, raw.subscribe_count);
    }
    policy.rules.push_back(std::move(rule));
  }
  return policy;
}

void Device::set_policy(const std::optional<AccessPolicy>& policy) const {
  agnocast_policy argument{};
  std::vector<agnocast_policy_rule> rules;
  std::vector<agnocast_principal> principals;
  if (policy) {
    if (policy->rules.size() > AGNOCAST_POLICY_RULES_MAX) {
      throw std::invalid_argument("the access policy has " + std::to_string(policy->rules.size()) +
                                  " rules: at most " + std::to_string(AGNOCAST_POLICY_RULES_MAX));
    }
    for (const AccessRule& rule : policy->rules) {
      const TopicPattern pattern = parse_topic_pattern(rule.topics);
      agnocast_policy_rule raw{};
      copy_name(raw.prefix, sizeof raw.prefix, pattern.prefix, "access rule topics");
      raw.match = match_kind(pattern.match);
      raw.first_principal = static_cast<std::uint32_t>(principals.size());
      const auto add = [&](const std::optional<std::vector<AccessPrincipal>>& list,
                           std::uint32_t flag, std::uint32_t& count) {
        if (!list) return;
        raw.flags |= flag;
        for (const AccessPrincipal& principal : *list) {
          principals.push_back(
              {principal_kind(principal.kind),
               principal.kind == AccessPrincipal::Kind::anyone ? 0 : principal.id});
        }
        count = static_cast<std::uint32_t>(list->size());
      };
      add(rule.publish, AGNOCAST_RULE_PUBLISH, raw.publish_count);
      add(rule.subscribe, AGNOCAST_RULE_SUBSCRIBE, raw.subscribe_count);
      rules.push_back(raw);
    }
    if (principals.size() > AGNOCAST_POLICY_PRINCIPALS_MAX) {
      throw std::invalid_argument("the access policy names " + std::to_string(principals.size()) +
                                  " users and groups in all: at most " +
                                  std::to_string(AGNOCAST_POLICY_PRINCIPALS_MAX));
    }
    argument.flags =
        AGNOCAST_POLICY_PRESENT | (policy->default_allow ? 0U : AGNOCAST_POLICY_DEFAULT_DENY);
    argument.rule_count = static_cast<std::uint32_t>(rules.size());
    argument.rules = reinterpret_cast<std::uintptr_t>(rules.data());
    argument.principal_count = static_cast<std::uint32_t>(principals.size());
    argument.principals = reinterpret_cast<std::uintptr_t>(principals.data());
  }
  if (int err = call(fd_, AGNOCAST_IOC_SET_POLICY, &argument)) {
    fail("SET_POLICY", err,
         err == EPERM ? "setting the access policy needs CAP_SYS_ADMIN (agnocastd does it)"
                      : std::string_view{});
  }
}

std::vector<TopicSummary> Device::list_topics() const {
  // The list may grow between the count and the fetch: retry until it fits.
  std::vector<agnocast_topic_summary> raw(16);
  agnocast_list_topics argument{};
  for (;;) {
    argument = {};
    argument.topics = reinterpret_cast<std::uintptr_t>(raw.data());
    argument.capacity = static_cast<std::uint32_t>(raw.size());
    if (int err = call(fd_, AGNOCAST_IOC_LIST_TOPICS, &argument)) fail("LIST_TOPICS", err);
    if (argument.total <= raw.size()) break;
    raw.resize(argument.total + 16);
  }
  std::vector<TopicSummary> topics;
  for (std::uint32_t i = 0; i < argument.total; ++i) {
    topics.push_back({bounded_string(raw[i].name, sizeof raw[i].name), raw[i].publishers,
                      raw[i].subscribers, bounded_string(raw[i].type_name, sizeof raw[i].type_name),
                      raw[i].type_hash});
  }
  return topics;
}

std::optional<std::vector<std::uint8_t>> Device::topic_schema(const std::string& topic) const {
  std::vector<std::uint8_t> schema(AGNOCAST_SCHEMA_MAX);
  agnocast_topic_schema argument{};
  copy_name(argument.name, sizeof argument.name, topic, "topic name");
  argument.schema = reinterpret_cast<std::uintptr_t>(schema.data());
  argument.capacity = static_cast<std::uint32_t>(schema.size());
  if (int err = call(fd_, AGNOCAST_IOC_TOPIC_SCHEMA, &argument)) {
    if (err == ENOENT || err == ENODATA) return std::nullopt;
    fail("TOPIC_SCHEMA", err);
  }
  schema.resize(argument.size);
  return schema;
}

bool Device::topic_info(const std::string& topic, TopicInfo& info) {
  std::vector<agnocast_publisher_info> publishers(8);
  std::vector<agnocast_subscriber_info> subscribers(8);
  agnocast_topic_info argument{};
  for (;;) {
    argument = {};
    copy_name(argument.name, sizeof argument.name, topic, "topic name");
    argument.publishers = reinterpret_cast<std::uintptr_t>(publishers.data());
    argument.publisher_capacity = static_cast<std::uint32_t>(publishers.size());
    argument.subscribers = reinterpret_cast<std::uintptr_t>(subscribers.data());
    argument.subscriber_capacity = static_cast<std::uint32_t>(subscribers.size());
    if (int err = call(fd_, AGNOCAST_IOC_TOPIC_INFO, &argument)) {
      if (err == ENOENT) return false;
      fail("TOPIC_INFO", err);
    }
    if (argument.publisher_total <= publishers.size() &&
        argument.subscriber_total <= subscribers.size()) {
      break;
    }
    publishers.resize(argument.publisher_total + 8);
    subscribers.resize(argument.subscriber_total + 8);
  }
  info = TopicInfo{};
  info.name = topic;
  info.entries = argument.entries;
  info.type_name = bounded_string(argument.type_name, sizeof argument.type_name);
  info.type_hash = argument.type_hash;
  info.schema_size = argument.schema_size;
  for (std::uint32_t i = 0; i < argument.publisher_total; ++i) {
    const auto& raw = publishers[i];
    info.publishers.push_back(
        PublisherInfo{raw.id, raw.pid, bounded_string(raw.node, sizeof raw.node), raw.depth,
                      (raw.flags & AGNOCAST_TRANSIENT_LOCAL) != 0, raw.published,
                      raw.published_bytes, raw.window, raw.uid});
  }
  for (std::uint32_t i = 0; i < argument.subscriber_total; ++i) {
    const auto& raw = subscribers[i];
    info.subscribers.push_back(SubscriberInfo{
        raw.id, raw.pid, bounded_string(raw.node, sizeof raw.node), raw.depth,
        (raw.flags & AGNOCAST_TRANSIENT_LOCAL) != 0, (raw.flags & AGNOCAST_POLLING) != 0,
        raw.unreceived, raw.held, raw.received, raw.dropped, raw.uid});
  }
  return true;
}

std::vector<ProcessInfo> Device::list_processes() const {
  std::vector<agnocast_process_info> raw(16);
  agnocast_list_processes argument{};
  for (;;) {
    argument = {};
    argument.processes = reinterpret_cast<std::uintptr_t>(raw.data());
    argument.capacity = static_cast<std::uint32_t>(raw.size());
    if (int err = call(fd_, AGNOCAST_IOC_LIST_PROCESSES, &argument)) {
      fail("LIST_PROCESSES", err);
    }
    if (argument.total <= raw.size()) break;
    raw.resize(argument.total + 16);
  }
  std::vector<ProcessInfo> processes;
  for (std::uint32_t i = 0; i < argument.total; ++i) {
    processes.push_back(ProcessInfo{raw[i].pid, raw[i].publishers, raw[i].subscribers,
                                    raw[i].pools_mapped, raw[i].pool_addr, raw[i].pool_size});
  }
  return processes;
}

std::vector<ExitRecord> Device::read_exit_records() const {
  std::vector<ExitRecord> records;
  agnocast_exit_record raw[32];
  for (;;) {
    const ssize_t got = ::read(fd_, raw, sizeof raw);
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN) break;
      const int err = errno;
      fail("read exit records", err,
           err == EPERM ? "reading exit records needs CAP_SYS_ADMIN (run as root, as agnocastd)"
                        : std::string_view{});
    }
    const std::size_t count = static_cast<std::size_t>(got) / sizeof raw[0];
    for (std::size_t i = 0; i < count; ++i) {
      ExitRecord record;
      switch (raw[i].kind) {
        case AGNOCAST_EXIT_QUEUE:
          record.kind = ExitRecord::Kind::queue;
          break;
        case AGNOCAST_EXIT_LOST:
          record.kind = ExitRecord::Kind::lost;
          break;
        default:
          record.kind = ExitRecord::Kind::process;
          break;
      }
      record.pid = raw[i].pid;
      if (record.kind == ExitRecord::Kind::lost) {
        record.lost_count = raw[i].subscriber_id;
      } else {
        record.subscriber_id = raw[i].subscriber_id;
      }
      record.topic = bounded_string(raw[i].topic, sizeof raw[i].topic);
      records.push_back(std::move(record));
    }
    if (count < std::size(raw)) break;
  }
  return records;
}

}  // namespace agnocast::detail
