// Every allocation the module's calls make fails once, in turn, on a kernel
// with fault injection (the debug kernel: failslab, and the kernel's
// /proc/thread-self/fail-nth, which fails the Nth allocation of the
// calling thread's next system calls).  Each call runs again and again with
// its 1st, 2nd, ... allocation failing until a run makes fewer.  A call
// whose allocation failed must fail with ENOMEM and leave nothing half made:
// no endpoint, entry or registration more than before, and the same call
// without the failure then succeeds.  KASAN sees every error path's memory
// accesses, and vm.debug.kmemleak, after the suite, every object an error
// path forgot to free.  Elsewhere the test is skipped.
#include <fcntl.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "test_util.h"

using namespace agnocast_test;

namespace {

const char* const kFailslab = "/sys/kernel/debug/failslab";

bool write_text(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  return ok;
}

// The calling thread's fail-nth, and failslab set to fail GFP_KERNEL
// allocations too, quietly (its defaults: only atomic ones, with a stack
// dump each).
class Injection {
 public:
  Injection() {
    if (::access(kFailslab, F_OK)) ::mount("debugfs", "/sys/kernel/debug", "debugfs", 0, nullptr);
    fd_ = ::open("/proc/thread-self/fail-nth", O_RDWR | O_CLOEXEC);
    if (fd_ < 0) return;
    ready_ = write_text(std::string(kFailslab) + "/ignore-gfp-wait", "N") &&
             write_text(std::string(kFailslab) + "/verbose", "0");
  }
  ~Injection() {
    write_text(std::string(kFailslab) + "/ignore-gfp-wait", "Y");
    write_text(std::string(kFailslab) + "/verbose", "2");
    if (fd_ >= 0) ::close(fd_);
  }
  bool ready() const { return ready_; }

  // Runs `call` (nothing but the system call: any other system call in it
  // would take the failure) with the nth allocation failing; false when
  // the call made fewer than n allocations, so none failed.
  bool with_nth_failing(unsigned n, const std::function<void()>& call) {
    const std::string armed = std::to_string(n);
    if (::pwrite(fd_, armed.data(), armed.size(), 0) != static_cast<ssize_t>(armed.size())) {
      ADD_FAILURE() << "fail-nth cannot be set: " << std::strerror(errno);
      return false;
    }
    call();
    char left[16] = {};
    const ssize_t got = ::pread(fd_, left, sizeof(left) - 1, 0);
    ::pwrite(fd_, "0", 1, 0);
    return got > 0 && std::atoi(left) == 0;
  }

 private:
  int fd_ = -1;
  bool ready_ = false;
};

// For n = 1, 2, ...: `prepare` unarmed, then `call` with its nth allocation
// failing, then `check` with n and whether one failed, until a run made
// fewer than n (it fails when the call made no allocation at all).
void each_allocation_failing(Injection& injection, const std::function<void()>& prepare,
                             const std::function<int()>& call,
                             const std::function<void(unsigned, int)>& check) {
  for (unsigned n = 1; n < 500; ++n) {
    prepare();
    int result = 0;
    const bool failed = injection.with_nth_failing(n, [&] { result = call(); });
    if (!failed) {
      check(0, result);
      // The log says how far each call went.
      static unsigned calls = 0;
      std::printf("%s, call %u: %u allocation(s) failed in turn\n",
                  ::testing::UnitTest::GetInstance()->current_test_info()->name(), ++calls, n - 1);
      EXPECT_GT(n, 1U) << "the call made no allocation: nothing was tested";
      return;
    }
    check(n, result);
    if (::testing::Test::HasFatalFailure()) return;
  }
  ADD_FAILURE() << "a call made 500 allocations or more";
}

// After one of its allocations failed, a call either failed with ENOMEM or
// succeeded all the same (the allocation had a fallback: kvmalloc's vmalloc).
#define EXPECT_ENOMEM_OR_SUCCESS(ret, n) \
  EXPECT_TRUE((ret) == 0 || (ret) == -ENOMEM) << "allocation " << (n) << " failed: " << (ret)

#define SKIP_WITHOUT_INJECTION(injection) \
  if (!(injection).ready())               \
  GTEST_SKIP() << "no fault injection in this kernel (the debug kernel has failslab)"

uint32_t publishers_of(int dev, const std::string& topic) {
  agnocast_topic_info info{};
  return topic_info(dev, topic, &info) ? 0 : info.publisher_total;
}

uint32_t subscribers_of(int dev, const std::string& topic) {
  agnocast_topic_info info{};
  return topic_info(dev, topic, &info) ? 0 : info.subscriber_total;
}

TEST(AllocFailure, OpeningTheDeviceFailsCleanly) {
  Injection injection;
  SKIP_WITHOUT_INJECTION(injection);
  int fd = -1, error = 0;
  each_allocation_failing(
      injection, [] {},
      [&] {
        fd = open_device();
        error = errno;
        return fd;
      },
      [&](unsigned n, int) {
        if (fd >= 0) {
          // The device answers on a descriptor it opened.
          agnocast_version version{};
          EXPECT_EQ(ioc(fd, AGNOCAST_IOC_GET_VERSION, &version), 0) << "allocation " << n;
          ::close(fd);
        } else {
          EXPECT_NE(n, 0U) << "open failed with no allocation failed";
          EXPECT_EQ(error, ENOMEM) << "allocation " << n;
        }
      });
}

TEST(AllocFailure, RegisteringFailsCleanly) {
  Injection injection;
  SKIP_WITHOUT_INJECTION(injection);
  const int dev = open_device();
  ASSERT_GE(dev, 0);
  // `reserved`: the slot was reserved before the call (step two), and a
  // failed call leaves it so.
  const auto left_nothing = [&](bool reserved) {
    return [&, reserved](unsigned n, int ret) {
      if (n) {
        EXPECT_ENOMEM_OR_SUCCESS(ret, n);
      }
      const bool registered = reserved || ret == 0;
      EXPECT_EQ(process_listed(dev, ::getpid()), registered) << "allocation " << n;
      EXPECT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), registered ? 0 : -ESRCH)
          << "allocation " << n;
      EXPECT_TRUE(eventually([&] { return !process_listed(dev, ::getpid()); }))
          << "a registration outlived its failure, allocation " << n;
    };
  };
  // Step one: the slot.
  agnocast_register_process reg{};
  each_allocation_failing(
      injection,
      [&] {
        reg = poisoned_request<agnocast_register_process>();
        reg.pool_fd = -1;
      },
      [&] { return ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &reg); }, left_nothing(false));
  // Step two: the pool, made and sealed unarmed, its slot reserved.
  Registration pool;
  agnocast_register_process attach{};
  each_allocation_failing(
      injection,
      [&] {
        if (pool.map) ::munmap(pool.map, pool.size);
        if (pool.memfd >= 0) ::close(pool.memfd);
        pool = Registration{};
        ASSERT_EQ(pool.reserve(dev), 0);
        pool.memfd = memfd_create("agnocast-test", MFD_CLOEXEC | MFD_ALLOW_SEALING);
        ASSERT_EQ(ftruncate(pool.memfd, static_cast<off_t>(pool.size)), 0);
        pool.map = mmap(reinterpret_cast<void*>(pool.addr), pool.size, PROT_READ | PROT_WRITE,
                        MAP_SHARED | MAP_FIXED_NOREPLACE, pool.memfd, 0);
        ASSERT_NE(pool.map, MAP_FAILED);
        ASSERT_EQ(fcntl(pool.memfd, F_ADD_SEALS, AGNOCAST_POOL_SEALS), 0);
        ASSERT_EQ(fchmod(pool.memfd, 0444), 0);
        attach = poisoned_request<agnocast_register_process>();
        attach.pool_fd = pool.memfd;
      },
      [&] { return ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &attach); }, left_nothing(true));
  if (pool.map) ::munmap(pool.map, pool.size);
  if (pool.memfd >= 0) ::close(pool.memfd);
  ::close(dev);
}

// A registered process with the device open, for the calls below.
class AllocFailureRegistered : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!injection.ready())
      GTEST_SKIP() << "no fault injection in this kernel (the debug kernel has failslab)";
    dev = open_device();
    ASSERT_GE(dev, 0);
    ASSERT_EQ(registration.full(dev), 0);
  }
  void TearDown() override {
    if (dev < 0) return;
    registration.drop();
    EXPECT_TRUE(eventually([&] { return !process_listed(dev, ::getpid()); }));
    ::close(dev);
  }

  // A pool address no entry uses yet.
  uint64_t fresh_address() { return registration.addr + 64 * used_addresses++; }

  Injection injection;
  int dev = -1;
  Registration registration;
  uint64_t used_addresses = 0;
};

TEST_F(AllocFailureRegistered, AddingEndpointsFailsCleanly) {
  // The first publisher of a topic makes the topic, with a schema; then a
  // subscriber with a deep queue, on the topic it made.
  const std::string topic = "/alloc_failure/endpoints";
  std::vector<unsigned char> schema(100, 0x5A);
  agnocast_add_endpoint ep{};
  const auto request = [&](uint32_t depth) {
    ep = endpoint(topic, depth);
    std::strncpy(ep.type_name, "alloc/msg/Failure", sizeof(ep.type_name) - 1);
    ep.type_hash = 42;
    ep.schema = uptr(schema.data());
    ep.schema_size = static_cast<uint32_t>(schema.size());
  };
  const auto left_nothing = [&](unsigned long remove, uint32_t (*count)(int, const std::string&)) {
    return [&, remove, count](unsigned n, int ret) {
      if (n) {
        EXPECT_ENOMEM_OR_SUCCESS(ret, n);
      }
      EXPECT_EQ(count(dev, topic), ret ? 0U : 1U) << "allocation " << n;
      if (!ret) {
        agnocast_remove_endpoint gone{ep.topic_handle, ep.id};
        EXPECT_EQ(ioc(dev, remove, &gone), 0);
      }
    };
  };
  each_allocation_failing(
      injection, [&] { request(10); }, [&] { return ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep); },
      left_nothing(AGNOCAST_IOC_REMOVE_PUBLISHER, publishers_of));
  // A publisher of the same type keeps the topic while subscribers come and go.
  request(10);
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), 0);
  each_allocation_failing(
      injection, [&] { request(1000); }, [&] { return ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep); },
      left_nothing(AGNOCAST_IOC_REMOVE_SUBSCRIBER, subscribers_of));
}

TEST_F(AllocFailureRegistered, PublishReceiveAndReleaseFailCleanly) {
  const std::string topic = "/alloc_failure/data";
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(registration.dev, topic, 10, &pub), 0);
  ASSERT_EQ(add_subscriber(registration.dev, topic, 16, &sub), 0);

  // PUBLISH: its buffers made unarmed.
  std::vector<uint32_t> wake(AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX);
  std::vector<uint64_t> reclaim(65);
  agnocast_publish arg{};
  each_allocation_failing(
      injection,
      [&] {
        arg = poisoned<agnocast_publish>();
        arg.topic_handle = pub.handle;
        arg.publisher_id = pub.id;
        arg.addr = fresh_address();
        arg.bytes = 8;
        arg.wake_ids = uptr(wake.data());
        arg.wake_capacity = static_cast<uint32_t>(wake.size());
        arg.reclaim = uptr(reclaim.data());
        arg.reclaim_capacity = 64;
        arg.flags = 0;
        arg.to_subscriber = 0;
        arg.reserved = 0;
      },
      [&] { return ioc(dev, AGNOCAST_IOC_PUBLISH, &arg); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        // Every publish that succeeded, and none other, waits for the subscriber.
        ReceiveResult got;
        ASSERT_EQ(receive(dev, sub, &got), 0);
        EXPECT_EQ(got.entries.size(), ret ? 0U : 1U) << "allocation " << n;
        for (const auto& entry : got.entries) {
          EXPECT_EQ(release(dev, sub, entry.entry_id), 0);
        }
      });

  // RECEIVE: an entry waits each time, and is either handed over or still waits.
  std::vector<agnocast_entry> entries(64);
  std::vector<agnocast_pool> pools(16);
  agnocast_receive rx{};
  each_allocation_failing(
      injection,
      [&] {
        ASSERT_EQ(publish(dev, pub, fresh_address()), 0);
        rx = poisoned<agnocast_receive>();
        rx.topic_handle = sub.handle;
        rx.subscriber_id = sub.id;
        rx.entries = uptr(entries.data());
        rx.pools = uptr(pools.data());
        rx.entry_capacity = 64;
        rx.pool_capacity = 16;
        rx.release_count = 0;
      },
      [&] { return ioc(dev, AGNOCAST_IOC_RECEIVE, &rx); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        std::vector<uint64_t> held;
        if (!ret)
          for (uint32_t i = 0; i < rx.entry_count; ++i) held.push_back(entries[i].entry_id);
        ReceiveResult rest;
        ASSERT_EQ(receive(dev, sub, &rest), 0);
        for (const auto& entry : rest.entries) held.push_back(entry.entry_id);
        EXPECT_EQ(held.size(), 1U) << "the entry was lost or doubled, allocation " << n;
        for (uint64_t id : held) {
          EXPECT_EQ(release(dev, sub, id), 0);
        }
      });

  // RELEASE of a list longer than the module copies on its stack: the
  // entries are given back all or none.
  std::vector<uint64_t> ids;
  agnocast_release rel{};
  each_allocation_failing(
      injection,
      [&] {
        ids.clear();
        for (int i = 0; i < 12; ++i) {
          ASSERT_EQ(publish(dev, pub, fresh_address()), 0);
        }
        for (ReceiveResult got; receive(dev, sub, &got) == 0 && !got.entries.empty();) {
          for (const auto& entry : got.entries) ids.push_back(entry.entry_id);
        }
        ASSERT_EQ(ids.size(), 12U);
        rel = {sub.handle, sub.id, uptr(ids.data()), static_cast<uint32_t>(ids.size()), 0};
      },
      [&] { return ioc(dev, AGNOCAST_IOC_RELEASE, &rel); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        if (ret) {
          EXPECT_EQ(release_list(dev, sub, ids), 0) << "a failed release gave some back";
        }
        agnocast_topic_info info{};
        std::vector<agnocast_subscriber_info> subs;
        ASSERT_EQ(topic_info(dev, topic, &info, nullptr, &subs), 0);
        ASSERT_EQ(subs.size(), 1U);
        EXPECT_EQ(subs[0].held, 0U) << "allocation " << n;
      });
}

TEST_F(AllocFailureRegistered, InspectionAndPolicyFailCleanly) {
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/alloc_failure/seen", 10, &pub), 0);
  std::vector<agnocast_topic_summary> topics(64);
  agnocast_list_topics list{};
  each_allocation_failing(
      injection,
      [&] {
        list = {uptr(topics.data()), 64, 0, 0, 0};
      },
      [&] { return ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &list); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        if (!ret) {
          EXPECT_GE(list.total, 1U);
        }
      });
  std::vector<agnocast_publisher_info> pubs(64);
  std::vector<agnocast_subscriber_info> subs(64);
  agnocast_topic_info info{};
  each_allocation_failing(
      injection,
      [&] {
        info = poisoned<agnocast_topic_info>();
        std::memset(info.name, 0, sizeof(info.name));
        std::strncpy(info.name, "/alloc_failure/seen", sizeof(info.name) - 1);
        info.publishers = uptr(pubs.data());
        info.subscribers = uptr(subs.data());
        info.publisher_capacity = 64;
        info.subscriber_capacity = 64;
      },
      [&] { return ioc(dev, AGNOCAST_IOC_TOPIC_INFO, &info); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        if (!ret) {
          EXPECT_EQ(info.publisher_total, 1U);
        }
      });
  // A policy set, read back and cleared, each under failures.
  std::vector<agnocast_policy_rule> rules(1);
  std::strncpy(rules[0].prefix, "/alloc_failure", sizeof(rules[0].prefix) - 1);
  rules[0].match = AGNOCAST_MATCH_DESCENDANTS;
  rules[0].flags = AGNOCAST_RULE_PUBLISH | AGNOCAST_RULE_SUBSCRIBE;
  rules[0].publish_count = 1;
  rules[0].subscribe_count = 1;
  std::vector<agnocast_principal> principals = {{AGNOCAST_PRINCIPAL_ANYONE, 0},
                                                {AGNOCAST_PRINCIPAL_ANYONE, 0}};
  agnocast_policy policy{};
  const auto set = [&] {
    policy = {AGNOCAST_POLICY_PRESENT, 1, 2, 0, uptr(rules.data()), uptr(principals.data())};
  };
  each_allocation_failing(
      injection, set, [&] { return ioc(dev, AGNOCAST_IOC_SET_POLICY, &policy); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
      });
  std::vector<agnocast_policy_rule> got_rules(4);
  std::vector<agnocast_principal> got_principals(8);
  each_allocation_failing(
      injection,
      [&] {
        set();
        ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &policy), 0);
        policy = {0, 4, 8, 0, uptr(got_rules.data()), uptr(got_principals.data())};
      },
      [&] { return ioc(dev, AGNOCAST_IOC_GET_POLICY, &policy); },
      [&](unsigned n, int ret) {
        if (n) {
          EXPECT_ENOMEM_OR_SUCCESS(ret, n);
        }
        if (!ret) {
          EXPECT_EQ(policy.rule_count, 1U);
        }
      });
  agnocast_policy none{};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &none), 0);
}

}  // namespace
