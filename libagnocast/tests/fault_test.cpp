// Faults on a message's path, one per step, against a real subscriber (a
// node, a callback subscription and an executor spinning in a child process)
// and publishers in other processes: a publisher killed before PUBLISH,
// between PUBLISH and its notification (through the UAPI: the library never
// stops there) and after it; a subscriber killed in its callback and while
// its releases wait; descriptors exhausted on either side; the subscriber's
// queue removed or replaced under it; mqueue's msg_max reached.  Every wait
// is bounded: every message within kDeliveryLimit, what a dead process left
// gone within kCleanupLimit.  agnocastd runs beside the suite, as it does in
// production: it removes a killed process's queue (agnocastd/README.md).
#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <mqueue.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "test_util.h"

namespace faults {

struct Sample {
  std::uint64_t seq = 0;
  std::uint64_t check = 0;
};

inline std::uint64_t check_of(std::uint64_t seq) { return seq * 0x9E3779B97F4A7C15ULL ^ 0xFA17; }

}  // namespace faults

AGNOCAST_MESSAGE(faults::Sample, "faults/msg/Sample", seq, check);

namespace faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using agnocast::QoS;

// Generous for TCG: one message takes well under a millisecond natively.
constexpr auto kDeliveryLimit = 10s;
// agnocastd removes a dead process's queues within 2 s (SPEC §7); the
// module's teardown runs from a workqueue.
constexpr auto kCleanupLimit = 10s;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// What one subscriber child reports, in memory shared with the test.
struct SubscriberSlot {
  static constexpr std::size_t seqs_max = 1024;
  std::atomic<std::uint32_t> ready{0};
  std::atomic<std::uint32_t> id{0};
  std::atomic<std::uint32_t> count{0};
  std::atomic<std::uint32_t> corrupt{0};
  std::atomic<std::int64_t> last_receive_ns{0};
  std::atomic<std::uint64_t> seqs[seqs_max]{};
  // spin_once threw agnocast::DeviceError: how often, and its errno.
  std::atomic<std::uint32_t> errors{0};
  std::atomic<int> error_code{0};
  // The test asks the child to lift its descriptor limit again.
  std::atomic<std::uint32_t> lift_limit{0};
};

// What one publisher child does on the test's word.
struct PublisherSlot {
  std::atomic<std::uint32_t> ready{0};
  std::atomic<std::uint64_t> target{0};  // messages to have published
  std::atomic<std::uint64_t> done{0};
  std::atomic<std::int64_t> last_publish_ns{0};
  // Warnings of the library (its log handler) that name EMFILE.
  std::atomic<std::uint32_t> emfile_warnings{0};
  // The raw publisher: subscribers its PUBLISH listed for a notification.
  std::atomic<std::uint32_t> listed{0};
  std::atomic<std::uint32_t> listed_id{~0U};
};

struct Board {
  std::atomic<std::uint32_t> stop{0};
  SubscriberSlot subscribers[2];
  PublisherSlot publishers[3];
};

// A child's descriptor limit at the lowest free descriptor: every descriptor
// it opens from now on fails with EMFILE. Returns the limit it had.
rlimit exhaust_descriptors() {
  rlimit old{};
  ::getrlimit(RLIMIT_NOFILE, &old);
  const int lowest_free = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  ::close(lowest_free);
  rlimit low = old;
  low.rlim_cur = static_cast<rlim_t>(lowest_free);
  ::setrlimit(RLIMIT_NOFILE, &low);
  return old;
}

bool descriptors_exhausted() {
  const int fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (fd >= 0) ::close(fd);
  return fd < 0 && errno == EMFILE;
}

using agnocast_test::fork_child;

// The child's exit status (128 + signal); kills it after limit.
int wait_child(pid_t pid, std::chrono::milliseconds limit) {
  int status = 0;
  const bool exited = agnocast_test::eventually(
      [&] { return ::waitpid(pid, &status, WNOHANG) == pid; }, limit, 5ms);
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// True once the child stopped (SIGSTOP), within limit.
bool wait_stopped(pid_t pid, std::chrono::milliseconds limit) {
  int status = 0;
  return agnocast_test::eventually(
      [&] { return ::waitpid(pid, &status, WNOHANG | WUNTRACED) == pid && WIFSTOPPED(status); },
      limit, 5ms);
}

std::string queue_file(const std::string& queue) { return "/dev/mqueue" + queue; }

bool queue_exists(const std::string& queue) {
  return ::access(queue_file(queue).c_str(), F_OK) == 0;
}

// The queue files in /dev/mqueue of topic's subscribers.
std::vector<std::string> queues_of(const std::string& topic) {
  std::string prefix = agnocast::queue_name(topic, 0);
  prefix = prefix.substr(1, prefix.size() - 2);  // "/a_b@0" -> "a_b@"
  std::vector<std::string> names;
  if (DIR* dir = ::opendir("/dev/mqueue")) {
    while (const dirent* entry = ::readdir(dir)) {
      if (std::string(entry->d_name).starts_with(prefix)) names.push_back(entry->d_name);
    }
    ::closedir(dir);
  }
  return names;
}

bool process_listed(pid_t pid) {
  const auto processes = agnocast::list_processes();
  return std::any_of(processes.begin(), processes.end(),
                     [&](const auto& process) { return process.pid == pid; });
}

bool has_endpoint_of(const agnocast::TopicInfo& info, pid_t pid) {
  return std::any_of(info.publishers.begin(), info.publishers.end(),
                     [&](const auto& p) { return p.pid == pid; }) ||
         std::any_of(info.subscribers.begin(), info.subscribers.end(),
                     [&](const auto& s) { return s.pid == pid; });
}

// `agnocast-cli --json topic info`: the pids of its publishers and subscribers.
struct CliTopic {
  std::vector<pid_t> publishers;
  std::vector<pid_t> subscribers;
};

std::vector<pid_t> pids_in(const std::string& json) {
  std::vector<pid_t> pids;
  for (std::size_t at = json.find("\"pid\":"); at != std::string::npos;
       at = json.find("\"pid\":", at + 1)) {
    pids.push_back(static_cast<pid_t>(std::stol(json.substr(at + 6))));
  }
  return pids;
}

std::optional<CliTopic> cli_topic(const std::string& topic) {
  const agnocast_test::Outcome outcome =
      agnocast_test::run_shell("agnocast-cli --json topic info " + topic, "cli-topic-info");
  if (outcome.code != 0) return std::nullopt;
  // The object's keys are sorted: name, publishers, subscribers, type, ...
  const std::size_t publishers = outcome.out.find("\"publishers\":[");
  const std::size_t subscribers = outcome.out.find("\"subscribers\":[");
  const std::size_t type = outcome.out.find("],\"type\":");
  if (publishers == std::string::npos || subscribers == std::string::npos ||
      type == std::string::npos || !(publishers < subscribers && subscribers < type)) {
    return std::nullopt;
  }
  return CliTopic{pids_in(outcome.out.substr(publishers, subscribers - publishers)),
                  pids_in(outcome.out.substr(subscribers, type - subscribers))};
}

// agnocastd beside the whole suite, with no configuration of its own.
class Daemon : public ::testing::Environment {
 public:
  void SetUp() override {
    char exe[4096] = {};
    ASSERT_GT(::readlink("/proc/self/exe", exe, sizeof exe - 1), 0);
    std::string path(exe);
    path = path.substr(0, path.rfind('/') + 1) + "agnocastd";
    agnocast_test::write_file("fault-agnocastd.json", "{}\n");
    pid_ = agnocast_test::spawn({path, "--no-load", "--config", "fault-agnocastd.json"},
                                "fault-agnocastd.log");
    const std::string pid_field = "\"pid\":" + std::to_string(pid_) + ",";
    ASSERT_TRUE(agnocast_test::eventually(
        [&] {
          const std::string status = agnocast_test::slurp("/run/agnocast/agnocastd.json");
          return status.find(pid_field) != std::string::npos &&
                 status.find("\"running\":true") != std::string::npos;
        },
        30s))
        << "agnocastd did not become ready:\n"
        << agnocast_test::slurp("fault-agnocastd.log");
  }
  void TearDown() override {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    EXPECT_EQ(wait_child(pid_, 10s), 0) << agnocast_test::slurp("fault-agnocastd.log");
  }

 private:
  pid_t pid_ = -1;
};

[[maybe_unused]] const auto* const daemon_environment =
    ::testing::AddGlobalTestEnvironment(new Daemon);

// fs.mqueue.msg_max for one test.
class MsgMax {
 public:
  explicit MsgMax(int value) : old_(agnocast_test::slurp(path)) {
    agnocast_test::write_file(path, std::to_string(value) + "\n");
  }
  ~MsgMax() { agnocast_test::write_file(path, old_); }
  MsgMax(const MsgMax&) = delete;
  MsgMax& operator=(const MsgMax&) = delete;

 private:
  static constexpr char path[] = "/proc/sys/fs/mqueue/msg_max";
  const std::string old_;
};

class Faults : public ::testing::Test {
 protected:
  enum class SubscriberFault {
    none,
    stop_in_callback,      // SIGSTOP inside its first callback
    stop_after_callbacks,  // SIGSTOP after the first wake-up that delivered messages
    exhaust_descriptors,   // at its descriptor limit until told to lift it
  };

  void SetUp() override {
    void* memory =
        ::mmap(nullptr, sizeof(Board), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(memory, MAP_FAILED);
    board_ = new (memory) Board;
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    topic_ = std::string("/faults/") + test->name() + "_" + std::to_string(::getpid());
  }

  // Every child stops; those not killed exit 0; the topic and its queues are gone.
  void TearDown() override {
    board_->stop = 1;
    for (const Child& child : children_) {
      if (child.reaped) continue;
      ::kill(child.pid, SIGCONT);  // one a failed check left stopped
      EXPECT_EQ(wait_child(child.pid, 20s), 0)
          << "child " << child.pid << " (" << child.what << ")";
    }
    EXPECT_TRUE(
        agnocast_test::eventually([&] { return !agnocast::topic_info(topic_); }, kCleanupLimit))
        << "the topic still has endpoints after every process ended";
    EXPECT_TRUE(agnocast_test::eventually([&] { return queues_of(topic_).empty(); }, kCleanupLimit))
        << "queues left: " << queues_of(topic_).size();
    board_->~Board();
    ::munmap(board_, sizeof(Board));
  }

  void adopt(pid_t pid, const std::string& what) { children_.push_back({pid, what, false}); }

  // Waits for a child that ends itself (128 + signal), at most limit.
  int reap(pid_t pid, std::chrono::milliseconds limit = 20s) {
    for (Child& child : children_) {
      if (child.pid == pid) child.reaped = true;
    }
    return wait_child(pid, limit);
  }

  // The fault: SIGKILL.
  void kill_child(pid_t pid) {
    ::kill(pid, SIGKILL);
    reap(pid);
  }

  // A subscriber child: a node with one callback subscription of depth,
  // spun by a SingleThreadedExecutor until the test ends.
  pid_t start_subscriber(int slot_index, std::size_t depth,
                         SubscriberFault fault = SubscriberFault::none) {
    SubscriberSlot& slot = board_->subscribers[slot_index];
    const std::string topic = topic_;
    Board* board = board_;
    const pid_t pid = fork_child([&slot, board, topic, depth, fault] {
      agnocast::Node node{"fault_listener"};
      auto subscription = node.create_subscription<Sample>(
          topic, QoS{depth}, [&](const agnocast::ipc_shared_ptr<const Sample>& message) {
            if (message->check != check_of(message->seq)) ++slot.corrupt;
            const std::uint32_t index = slot.count.load();
            if (index < SubscriberSlot::seqs_max) slot.seqs[index] = message->seq;
            slot.last_receive_ns = now_ns();
            slot.count = index + 1;
            if (fault == SubscriberFault::stop_in_callback && index == 0) ::raise(SIGSTOP);
          });
      agnocast::SingleThreadedExecutor executor;
      executor.add_node(node);
      slot.id = subscription->id();
      std::optional<rlimit> limit;
      if (fault == SubscriberFault::exhaust_descriptors) {
        limit = exhaust_descriptors();
        if (!descriptors_exhausted()) return 3;
      }
      slot.ready = 1;
      while (!board->stop) {
        if (limit && slot.lift_limit) {
          ::setrlimit(RLIMIT_NOFILE, &*limit);
          limit.reset();
        }
        try {
          const bool handled = executor.spin_once(20ms);
          // Not at the wake-up it gives itself when its queue is new.
          if (handled && slot.count && fault == SubscriberFault::stop_after_callbacks) {
            ::raise(SIGSTOP);
          }
        } catch (const agnocast::DeviceError& error) {
          if (fault != SubscriberFault::exhaust_descriptors) throw;
          slot.error_code = error.code();
          ++slot.errors;
        }
      }
      return slot.corrupt ? 2 : 0;
    });
    adopt(pid, "subscriber");
    EXPECT_TRUE(agnocast_test::eventually([&] { return slot.ready.load() != 0; }, 20s))
        << "the subscriber did not start";
    return pid;
  }

  // A publisher child: publishes seq first_seq, first_seq + 1, ... whenever
  // the test raises its target (publish()), never more than pace ahead of
  // subscriber 0 when pace is not 0, and stays until the test ends.
  pid_t start_publisher(int slot_index, std::size_t depth, std::uint64_t first_seq,
                        std::uint64_t pace = 0, bool exhaust = false) {
    PublisherSlot& slot = board_->publishers[slot_index];
    const std::string topic = topic_;
    Board* board = board_;
    const pid_t pid = fork_child([&slot, board, topic, depth, first_seq, pace, exhaust] {
      const std::string emfile = std::strerror(EMFILE);
      agnocast::set_log_handler([&slot, emfile](agnocast::LogLevel, std::string_view message) {
        if (message.find(emfile) != std::string_view::npos) ++slot.emfile_warnings;
      });
      agnocast::Node node{"fault_talker"};
      auto publisher = node.create_publisher<Sample>(topic, QoS{depth});
      if (exhaust) {
        exhaust_descriptors();
        if (!descriptors_exhausted()) return 3;
      }
      slot.ready = 1;
      const SubscriberSlot& reader = board->subscribers[0];
      while (!board->stop) {
        const std::uint64_t done = slot.done;
        if (done == slot.target || (pace && done - reader.count >= pace)) {
          std::this_thread::sleep_for(1ms);
          continue;
        }
        auto message = publisher->borrow_loaned_message();
        message->seq = first_seq + done;
        message->check = check_of(message->seq);
        publisher->publish(std::move(message));
        slot.last_publish_ns = now_ns();
        slot.done = done + 1;
      }
      return 0;
    });
    adopt(pid, "publisher");
    EXPECT_TRUE(agnocast_test::eventually([&] { return slot.ready.load() != 0; }, 20s))
        << "the publisher did not start";
    return pid;
  }

  // Publisher slot_index publishes count more messages; true once it has.
  bool publish(int slot_index, std::uint64_t count,
               std::chrono::milliseconds limit = kDeliveryLimit) {
    PublisherSlot& slot = board_->publishers[slot_index];
    const std::uint64_t target = slot.target + count;
    slot.target = target;
    return agnocast_test::eventually([&] { return slot.done.load() == target; }, limit, 1ms);
  }

  // True once subscriber slot_index has received count messages in all,
  // within limit; prints how long after the last publish it had them.
  bool received(int slot_index, std::uint32_t count, const std::string& what,
                std::chrono::milliseconds limit = kDeliveryLimit) {
    const SubscriberSlot& slot = board_->subscribers[slot_index];
    const bool all =
        agnocast_test::eventually([&] { return slot.count.load() >= count; }, limit, 1ms);
    std::int64_t last_publish = 0;
    for (const PublisherSlot& publisher : board_->publishers) {
      last_publish = std::max(last_publish, publisher.last_publish_ns.load());
    }
    if (all) {
      std::printf("%s: all %u received %.1f ms after the last publish\n", what.c_str(), count,
                  static_cast<double>(slot.last_receive_ns - last_publish) / 1e6);
    } else {
      std::printf("%s: %u of %u received within %lld ms\n", what.c_str(), slot.count.load(), count,
                  static_cast<long long>(limit.count()));
    }
    return all;
  }

  std::vector<std::uint64_t> seqs(int slot_index) const {
    const SubscriberSlot& slot = board_->subscribers[slot_index];
    std::vector<std::uint64_t> out;
    for (std::uint32_t i = 0; i < std::min<std::uint32_t>(slot.count, SubscriberSlot::seqs_max);
         ++i) {
      out.push_back(slot.seqs[i]);
    }
    return out;
  }

  static std::vector<std::uint64_t> range(std::uint64_t first, std::uint64_t count) {
    std::vector<std::uint64_t> out;
    for (std::uint64_t i = 0; i < count; ++i) out.push_back(first + i);
    return out;
  }

  std::optional<agnocast::SubscriberInfo> subscriber_info(pid_t pid) const {
    const auto info = agnocast::topic_info(topic_);
    if (!info) return std::nullopt;
    for (const auto& subscriber : info->subscribers) {
      if (subscriber.pid == pid) return subscriber;
    }
    return std::nullopt;
  }

  // The dead process is gone from the module (no endpoint on the topic, not
  // listed) and, a subscriber, its queue is gone (agnocastd).
  void expect_cleaned_up(pid_t pid, std::optional<std::uint32_t> subscriber_id) {
    const auto start = Clock::now();
    EXPECT_TRUE(agnocast_test::eventually(
        [&] {
          const auto info = agnocast::topic_info(topic_);
          return (!info || !has_endpoint_of(*info, pid)) && !process_listed(pid);
        },
        kCleanupLimit))
        << "process " << pid << " is still registered";
    if (!subscriber_id) return;
    const std::string queue = agnocast::queue_name(topic_, *subscriber_id);
    EXPECT_TRUE(agnocast_test::eventually([&] { return !queue_exists(queue); }, kCleanupLimit))
        << "agnocastd did not remove " << queue << " of dead process " << pid;
    std::printf(
        "dead subscriber %d: unregistered and its queue %s removed within %lld ms\n", pid,
        queue.c_str(),
        static_cast<long long>(
            std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count()));
  }

  // The publisher's messages that the killed subscriber held went back:
  // the topic keeps only the publisher's window of depth 1, and the
  // inspector shows the live endpoints only.
  void expect_reclaimed(pid_t dead, pid_t publisher) {
    EXPECT_TRUE(agnocast_test::eventually(
        [&] {
          const auto info = agnocast::topic_info(topic_);
          return info && info->entries == 1 && info->subscribers.empty() &&
                 info->publishers.size() == 1;
        },
        kCleanupLimit))
        << "entries left: "
        << (agnocast::topic_info(topic_) ? agnocast::topic_info(topic_)->entries : 0);
    const std::optional<CliTopic> cli = cli_topic(topic_);
    ASSERT_TRUE(cli) << agnocast_test::slurp("cli-topic-info.out")
                     << agnocast_test::slurp("cli-topic-info.err");
    EXPECT_EQ(cli->publishers, std::vector<pid_t>{publisher});
    EXPECT_TRUE(cli->subscribers.empty()) << "subscriber " << dead << " still shown";
  }

  struct Child {
    pid_t pid;
    std::string what;
    bool reaped;
  };
  Board* board_ = nullptr;
  std::string topic_;
  std::vector<Child> children_;
};

// 1. A publisher killed with a loan filled in but never published: nothing
// was promised; the next publisher's messages arrive.
TEST_F(Faults, PublisherKilledBeforePublish) {
  start_subscriber(0, 16);
  const std::string topic = topic_;
  const pid_t victim = fork_child([topic] {
    agnocast::Node node{"fault_victim"};
    auto publisher = node.create_publisher<Sample>(topic, QoS{4});
    auto message = publisher->borrow_loaned_message();
    message->seq = 900;
    message->check = check_of(900);
    ::raise(SIGSTOP);
    publisher->publish(std::move(message));
    return 0;
  });
  adopt(victim, "publisher killed before PUBLISH");
  ASSERT_TRUE(wait_stopped(victim, 20s));
  kill_child(victim);
  expect_cleaned_up(victim, std::nullopt);

  start_publisher(0, 16, 0);
  ASSERT_TRUE(publish(0, 5));
  EXPECT_TRUE(received(0, 5, "killed before PUBLISH"));
  EXPECT_EQ(seqs(0), range(0, 5));
}

// 1. A publisher killed after PUBLISH listed the subscriber for a
// notification but before it sent one: the module breaks the promise when the
// publisher's process dies, so the subscriber still reads the dead one's
// message and wakes for the next publisher's (before the fix it stayed
// listed as notified and slept through all of them).
TEST_F(Faults, PublisherKilledBetweenPublishAndNotification) {
  start_subscriber(0, 16);
  PublisherSlot& slot = board_->publishers[2];
  const std::uint32_t subscriber_id = board_->subscribers[0].id;
  const std::string topic = topic_;
  const pid_t victim = fork_child([&slot, topic, subscriber_id] {
    using namespace agnocast_test;
    const int dev = open_device();
    Registration registration;
    if (dev < 0 || registration.full(dev)) return 10;
    agnocast_add_endpoint request = endpoint(topic, 4, 0, "fault_raw_talker");
    std::memcpy(request.type_name, agnocast::message_traits<Sample>::type_name.data(),
                agnocast::message_traits<Sample>::type_name.size());
    request.type_hash = agnocast::message_traits<Sample>::type_hash;
    if (ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &request)) return 11;
    const Endpoint publisher{request.topic_handle, request.id};
    // A message where the library puts one: after room for its header,
    // which a fresh pool leaves zero.
    constexpr std::uint64_t offset = 4096;
    new (static_cast<char*>(registration.map) + offset) Sample{1000, check_of(1000)};
    PublishResult result;
    if (agnocast_test::publish(dev, publisher, registration.addr + offset, &result)) return 12;
    slot.last_publish_ns = now_ns();
    slot.listed = static_cast<std::uint32_t>(result.wake.size());
    if (!result.wake.empty()) slot.listed_id = result.wake[0];
    // Dies before it sends the notification PUBLISH asked for.
    ::raise(SIGKILL);
    return 13;
  });
  adopt(victim, "raw publisher killed after PUBLISH");
  EXPECT_EQ(reap(victim), 128 + SIGKILL);
  ASSERT_EQ(slot.listed.load(), 1U) << "PUBLISH did not list the subscriber";
  ASSERT_EQ(slot.listed_id.load(), subscriber_id);
  expect_cleaned_up(victim, std::nullopt);

  start_publisher(0, 16, 0);
  ASSERT_TRUE(publish(0, 5));
  EXPECT_TRUE(received(0, 6, "killed between PUBLISH and its notification"));
  EXPECT_EQ(seqs(0), (std::vector<std::uint64_t>{1000, 0, 1, 2, 3, 4}));
}

// 1. A publisher killed right after its publish() returned (notification
// sent): its message is still read, and so are the next publisher's.
TEST_F(Faults, PublisherKilledAfterNotification) {
  start_subscriber(0, 16);
  PublisherSlot& slot = board_->publishers[2];
  const std::string topic = topic_;
  const pid_t victim = fork_child([&slot, topic] {
    agnocast::Node node{"fault_victim"};
    auto publisher = node.create_publisher<Sample>(topic, QoS{4});
    auto message = publisher->borrow_loaned_message();
    message->seq = 500;
    message->check = check_of(500);
    publisher->publish(std::move(message));
    slot.last_publish_ns = now_ns();
    ::raise(SIGKILL);
    return 13;
  });
  adopt(victim, "publisher killed after its notification");
  EXPECT_EQ(reap(victim), 128 + SIGKILL);
  EXPECT_TRUE(received(0, 1, "the dead publisher's message"));
  expect_cleaned_up(victim, std::nullopt);

  start_publisher(0, 16, 0);
  ASSERT_TRUE(publish(0, 5));
  EXPECT_TRUE(received(0, 6, "killed after its notification"));
  EXPECT_EQ(seqs(0), (std::vector<std::uint64_t>{500, 0, 1, 2, 3, 4}));
}

// 2. A subscriber killed inside its callback (after RECEIVE, messages held):
// what it held goes back to the publisher, the module and the inspector forget
// it, agnocastd removes its queue, and a new subscriber reads new messages.
TEST_F(Faults, SubscriberKilledInCallback) {
  const pid_t victim = start_subscriber(0, 16, SubscriberFault::stop_in_callback);
  const std::uint32_t victim_id = board_->subscribers[0].id;
  const pid_t publisher = start_publisher(0, 1, 0);
  ASSERT_TRUE(publish(0, 3));
  ASSERT_TRUE(wait_stopped(victim, kDeliveryLimit)) << "the callback never ran";
  const auto held = subscriber_info(victim);
  ASSERT_TRUE(held);
  EXPECT_GE(held->held, 1U) << "the message in its callback is held";
  kill_child(victim);
  expect_cleaned_up(victim, victim_id);
  expect_reclaimed(victim, publisher);

  start_subscriber(1, 16);
  ASSERT_TRUE(publish(0, 5));
  EXPECT_TRUE(received(1, 5, "a new subscriber after one killed in its callback"));
  EXPECT_EQ(seqs(1), range(3, 5));
}

// 2. A subscriber killed after its callbacks returned, while their releases
// wait for its next RECEIVE or its timer (the deferred release): the same.
TEST_F(Faults, SubscriberKilledDuringDeferredRelease) {
  const pid_t victim = start_subscriber(0, 16, SubscriberFault::stop_after_callbacks);
  const std::uint32_t victim_id = board_->subscribers[0].id;
  const pid_t publisher = start_publisher(0, 1, 0);
  ASSERT_TRUE(publish(0, 3));
  ASSERT_TRUE(wait_stopped(victim, kDeliveryLimit)) << "no wake-up was handled";
  ASSERT_GE(board_->subscribers[0].count.load(), 1U);
  const auto held = subscriber_info(victim);
  ASSERT_TRUE(held);
  EXPECT_GE(held->held, 1U) << "the releases of its callbacks' messages wait";
  kill_child(victim);
  expect_cleaned_up(victim, victim_id);
  expect_reclaimed(victim, publisher);

  start_subscriber(1, 16);
  ASSERT_TRUE(publish(0, 5));
  EXPECT_TRUE(received(1, 5, "a new subscriber after one killed with releases waiting"));
  EXPECT_EQ(seqs(1), range(3, 5));
}

// 3. The publisher cannot open the subscriber's queue (EMFILE): it reports
// NOTIFY_FAILED, the module signals the subscriber's wake eventfd, and every
// message arrives (before the fix none did).
TEST_F(Faults, PublisherOutOfDescriptors) {
  start_subscriber(0, 16);
  start_publisher(0, 16, 0, 0, /*exhaust=*/true);
  for (int round = 0; round < 3; ++round) {
    ASSERT_TRUE(publish(0, 5));
    EXPECT_TRUE(received(0, 5 * (round + 1),
                         "publisher out of descriptors, round " + std::to_string(round + 1)));
  }
  EXPECT_EQ(seqs(0), range(0, 15));
  // The library warns once per queue it cannot open: once per wake-up here.
  EXPECT_GE(board_->publishers[0].emfile_warnings.load(), 3U)
      << "the publisher never failed to open the queue";
}

// 3. The subscriber at its descriptor limit cannot take the descriptor of a
// new publisher's pool: spin_once() throws DeviceError(EMFILE), the
// notification stays queued, and once descriptors are free again every
// message arrives.
TEST_F(Faults, SubscriberOutOfDescriptors) {
  start_subscriber(0, 16, SubscriberFault::exhaust_descriptors);
  start_publisher(0, 16, 0);
  ASSERT_TRUE(publish(0, 5));
  SubscriberSlot& slot = board_->subscribers[0];
  ASSERT_TRUE(agnocast_test::eventually([&] { return slot.errors.load() > 0; }, kDeliveryLimit))
      << "RECEIVE never failed";
  EXPECT_EQ(slot.error_code.load(), EMFILE);
  EXPECT_EQ(slot.count.load(), 0U);
  std::this_thread::sleep_for(100ms);
  std::printf("at its descriptor limit, spin_once threw %u times in 100 ms\n", slot.errors.load());
  const std::int64_t lifted = now_ns();
  slot.lift_limit = 1;
  EXPECT_TRUE(received(0, 5, "subscriber once descriptors were free again"));
  std::printf("all 5 received %.1f ms after the limit was lifted\n",
              static_cast<double>(slot.last_receive_ns - lifted) / 1e6);
  EXPECT_EQ(seqs(0), range(0, 5));
}

// 3. The same with a queue of one slot (fs.mqueue.msg_max 1), which the
// subscriber drains before it receives: the RECEIVE fails with EMFILE after
// the module counted it as looking (no watchdog then), so the wake-up taken
// must be queued again (handle_wakeup() in libagnocast/src/endpoints/subscription.cpp),
// or the messages wait for the next PUBLISH.
TEST_F(Faults, SubscriberOutOfDescriptorsWithOneSlotQueue) {
  const MsgMax msg_max(1);
  start_subscriber(0, 16, SubscriberFault::exhaust_descriptors);
  start_publisher(0, 16, 0);
  ASSERT_TRUE(publish(0, 5));
  SubscriberSlot& slot = board_->subscribers[0];
  ASSERT_TRUE(agnocast_test::eventually([&] { return slot.errors.load() > 0; }, kDeliveryLimit))
      << "RECEIVE never failed";
  EXPECT_EQ(slot.error_code.load(), EMFILE);
  slot.lift_limit = 1;
  EXPECT_TRUE(received(0, 5, "one-slot subscriber once descriptors were free again"));
  EXPECT_EQ(seqs(0), range(0, 5));
}

// 4. The subscriber's queue unlinked under it (as a mistaken stale sweep
// would): the publisher cannot open it and reports NOTIFY_FAILED.
TEST_F(Faults, QueueUnlinkedUnderSubscriber) {
  start_subscriber(0, 16);
  const std::string queue = agnocast::queue_name(topic_, board_->subscribers[0].id);
  ASSERT_EQ(::mq_unlink(queue.c_str()), 0) << std::strerror(errno);
  start_publisher(0, 16, 0);
  for (int round = 0; round < 3; ++round) {
    ASSERT_TRUE(publish(0, 5));
    EXPECT_TRUE(received(0, 5 * (round + 1), "queue unlinked, round " + std::to_string(round + 1)));
  }
  EXPECT_EQ(seqs(0), range(0, 15));
}

// 4. The subscriber's queue unlinked and another created under its name: the
// publisher's notifications go into the impostor, and only the module's
// watchdog (AGNOCAST_WAKE_WATCHDOG_MS after the listing) wakes the
// subscriber; before the fix nothing did.
TEST_F(Faults, QueueReplacedUnderSubscriber) {
  start_subscriber(0, 16);
  const std::string queue = agnocast::queue_name(topic_, board_->subscribers[0].id);
  ASSERT_EQ(::mq_unlink(queue.c_str()), 0) << std::strerror(errno);
  mq_attr attributes{};
  attributes.mq_maxmsg = 10;
  attributes.mq_msgsize = 8;
  const mqd_t impostor =
      ::mq_open(queue.c_str(), O_RDONLY | O_CREAT | O_EXCL | O_NONBLOCK, 0622, &attributes);
  ASSERT_NE(impostor, -1) << std::strerror(errno);
  start_publisher(0, 16, 0);
  for (int round = 0; round < 3; ++round) {
    ASSERT_TRUE(publish(0, 5));
    EXPECT_TRUE(received(0, 5 * (round + 1), "queue replaced, round " + std::to_string(round + 1)));
  }
  EXPECT_EQ(seqs(0), range(0, 15));
  mq_attr seen{};
  ::mq_getattr(impostor, &seen);
  EXPECT_GE(seen.mq_curmsgs, 1) << "the publisher never sent into the impostor";
  ::mq_close(impostor);
  ::mq_unlink(queue.c_str());
}

// Stops subscriber pid, fills its queue by hand, runs published(), lets it go on.
void fill_while_stopped(pid_t pid, const std::string& queue,
                        const std::function<void()>& published) {
  ::kill(pid, SIGSTOP);
  ASSERT_TRUE(wait_stopped(pid, 10s));
  const mqd_t sender = ::mq_open(queue.c_str(), O_WRONLY | O_NONBLOCK);
  ASSERT_NE(sender, -1) << std::strerror(errno);
  const char byte = 0;
  int sent = 0;
  while (::mq_send(sender, &byte, 1, 0) == 0) ++sent;
  EXPECT_EQ(errno, EAGAIN);
  ::mq_close(sender);
  std::printf("queue filled with %d notifications by hand\n", sent);
  published();
  ::kill(pid, SIGCONT);
}

// 5. A queue filled by hand to its capacity: a publisher's notification finds
// it full, which already means a wake-up waits. Nothing beyond the depth is
// lost; beyond it, exactly the oldest are dropped.
TEST_F(Faults, QueueFilledByHand) {
  const pid_t subscriber = start_subscriber(0, 8);
  const std::string queue = agnocast::queue_name(topic_, board_->subscribers[0].id);
  start_publisher(0, 16, 0);
  fill_while_stopped(subscriber, queue, [&] { ASSERT_TRUE(publish(0, 5)); });
  EXPECT_TRUE(received(0, 5, "queue full, 5 messages within the depth"));
  fill_while_stopped(subscriber, queue, [&] { ASSERT_TRUE(publish(0, 20)); });
  EXPECT_TRUE(received(0, 13, "queue full, 20 messages beyond the depth of 8"));
  std::vector<std::uint64_t> expected = range(0, 5);
  const std::vector<std::uint64_t> newest = range(17, 8);
  expected.insert(expected.end(), newest.begin(), newest.end());
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(seqs(0), expected);
  const auto info = subscriber_info(subscriber);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->dropped, 12U);
  EXPECT_EQ(info->unreceived, 0U);
}

// 5. A depth above fs.mqueue.msg_max (the queue holds fewer notifications
// than the subscriber keeps messages), and a queue of one slot: every message
// within the depth arrives, published while the subscriber was stopped or in a
// burst as fast as it reads.
class FaultsMsgMax : public Faults {
 protected:
  void run(int msg_max, std::size_t depth, std::uint64_t burst) {
    const MsgMax limit(msg_max);
    const pid_t subscriber = start_subscriber(0, depth);
    start_publisher(0, 16, 0, /*pace=*/depth);
    ::kill(subscriber, SIGSTOP);
    ASSERT_TRUE(wait_stopped(subscriber, 10s));
    ASSERT_TRUE(publish(0, depth));
    ::kill(subscriber, SIGCONT);
    EXPECT_TRUE(received(0, static_cast<std::uint32_t>(depth),
                         "msg_max " + std::to_string(msg_max) + ", depth " + std::to_string(depth) +
                             " published while stopped"));
    const auto start = Clock::now();
    ASSERT_TRUE(publish(0, burst, 60s));
    EXPECT_TRUE(
        received(0, static_cast<std::uint32_t>(depth + burst),
                 "msg_max " + std::to_string(msg_max) + ", burst of " + std::to_string(burst)));
    std::printf(
        "burst of %llu took %lld ms\n", static_cast<unsigned long long>(burst),
        static_cast<long long>(
            std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count()));
    EXPECT_EQ(seqs(0), range(0, depth + burst));
    const auto info = subscriber_info(subscriber);
    ASSERT_TRUE(info);
    EXPECT_EQ(info->dropped, 0U);
  }
};

TEST_F(FaultsMsgMax, DepthAboveMsgMax) { run(4, 64, 300); }

TEST_F(FaultsMsgMax, OneSlotQueue) { run(1, 16, 300); }

}  // namespace
}  // namespace faults
