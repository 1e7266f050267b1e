#include <fcntl.h>
#include <grp.h>
#include <mqueue.h>
#include <pwd.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "agnocast/errors.hpp"
#include "agnocast/inspect.hpp"
#include "agnocast/naming.hpp"
#include "agnocast/node.hpp"
#include "agnocast/schema_subscriber.hpp"
#include "agnocast/schema_topic.hpp"
#include "agnocast/signals.hpp"
#include "inspection_source.hpp"

namespace agnocast::cli {
namespace {

// "X.Y.Z" from the module's MODULE_VERSION, nullopt when absent or malformed.
std::optional<Version> sysfs_module_version() {
  std::ifstream in(std::string(module_sysfs_directory) + "/version");
  Version version;
  char dot1 = 0, dot2 = 0;
  if (in >> version.major >> dot1 >> version.minor >> dot2 >> version.patch && dot1 == '.' &&
      dot2 == '.') {
    return version;
  }
  return std::nullopt;
}

// getpwuid_r/getgrgid_r with a buffer that grows on ERANGE; nullopt when the
// database has no entry (or cannot be read: the id is shown instead).
template <typename Entry, typename Lookup, typename NameOf>
std::optional<std::string> name_of_id(std::uint32_t id, Lookup lookup, NameOf name_of) {
  std::vector<char> buffer(1024);
  for (;;) {
    Entry entry{};
    Entry* found = nullptr;
    const int error = lookup(id, &entry, buffer.data(), buffer.size(), &found);
    if (error == ERANGE && buffer.size() < (1u << 20)) {
      buffer.resize(buffer.size() * 2);
      continue;
    }
    if (found == nullptr) return std::nullopt;
    return std::string(name_of(*found));
  }
}

// topic echo's subscriber, in a node of its own so `topic info` names it.
class SystemTap final : public MessageTap {
 public:
  explicit SystemTap(const std::string& topic)
      : node_("agnocast_cli_echo"), subscriber_(node_, topic, QoS(echo_depth)) {}

  const Schema& schema() const override { return subscriber_.schema(); }
  bool take(const Reader& read) override {
    const std::optional<SchemaMessage> message = subscriber_.take();
    if (!message) return false;
    read(message->data(), message->readable());
    return true;
  }

 private:
  static constexpr std::size_t echo_depth = 10;
  Node node_;
  SchemaSubscriber subscriber_;
};

class SystemSource final : public InspectionSource {
 public:
  std::optional<Version> module_version() override {
    try {
      return agnocast::module_version();
    } catch (const DeviceError&) {
      // A user the device refuses can still read the version sysfs shows to all.
      if (std::optional<Version> version = sysfs_module_version()) return version;
      throw;
    }
  }
  std::vector<TopicSummary> list_topics() override { return agnocast::list_topics(); }
  std::vector<ProcessInfo> list_processes() override { return agnocast::list_processes(); }
  std::optional<TopicInfo> topic_info(const std::string& topic) override {
    return agnocast::topic_info(topic);
  }

  std::optional<AccessPolicy> access_policy() override { return agnocast::access_policy(); }
  std::optional<std::string> user_name(std::uint32_t uid) override {
    return name_of_id<passwd>(uid, ::getpwuid_r, [](const passwd& p) { return p.pw_name; });
  }
  std::optional<std::string> group_name(std::uint32_t gid) override {
    return name_of_id<group>(gid, ::getgrgid_r, [](const group& g) { return g.gr_name; });
  }

  std::vector<std::string> queue_files() override {
    std::vector<std::string> names;
    std::error_code error;
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(mqueue_directory), error)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }

  std::optional<QueueAttributes> queue_attributes(const std::string& queue_name) override {
    // Write-only, as any publisher may (queues are 0622), and nothing sent:
    // looking never consumes nor adds a wake-up.
    const mqd_t queue = ::mq_open(queue_name.c_str(), O_WRONLY | O_NONBLOCK);
    if (queue == static_cast<mqd_t>(-1)) return std::nullopt;
    struct mq_attr attr {};
    const int rc = ::mq_getattr(queue, &attr);
    ::mq_close(queue);
    if (rc != 0) return std::nullopt;
    return QueueAttributes{attr.mq_curmsgs, attr.mq_maxmsg};
  }

  std::unique_ptr<MessageTap> subscribe(const std::string& topic) override {
    install_signal_handlers();
    return std::make_unique<SystemTap>(topic);
  }
  Schema topic_schema(const std::string& topic) override {
    return resolve_schema_topic(topic).schema;
  }
  std::optional<RecordedDelays> recorded_delays(pid_t pid, const std::string& topic,
                                                std::uint32_t subscriber_id) override {
    return agnocast::recorded_delays(pid, topic, subscriber_id);
  }
  bool stop_requested() override { return !agnocast::ok(); }

  bool path_exists(const std::string& path) override { return ::access(path.c_str(), F_OK) == 0; }
  int path_access(const std::string& path, int mode) override {
    return ::access(path.c_str(), mode) == 0 ? 0 : errno;
  }
  std::optional<std::string> read_file(const std::string& path) override {
    std::ifstream in(path);
    if (!in) return std::nullopt;
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
  bool process_alive(pid_t pid) override {
    return pid > 0 && (::kill(pid, 0) == 0 || errno == EPERM);
  }

  std::optional<bool> exclusively_locked(const std::string& path) override {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    const bool locked = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    ::close(fd);  // also drops the shared lock if it was granted
    return locked;
  }

  double unix_time() override {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
  }
  double now_seconds() override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void sleep_seconds(double seconds) override {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  }
};

}  // namespace

InspectionSource& system_source() {
  static SystemSource source;
  return source;
}

}  // namespace agnocast::cli
