// Every command of the UAPI: each success path and each documented errno,
// with outputs poisoned before the call and checked after.
#include <poll.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <sys/prctl.h>

#include <algorithm>

#include "test_util.h"

using namespace agnocast_test;

namespace {

// The ABI: sizes are pinned so that no field moves unnoticed.
static_assert(sizeof(agnocast_version) == 16);
static_assert(sizeof(agnocast_register_process) == 32);
static_assert(sizeof(agnocast_add_endpoint) == 552);
static_assert(sizeof(agnocast_remove_endpoint) == 8);
static_assert(sizeof(agnocast_publish) == 80);
static_assert(sizeof(agnocast_reclaim) == 24);
static_assert(sizeof(agnocast_entry) == 24);
static_assert(sizeof(agnocast_pool) == 24);
static_assert(sizeof(agnocast_receive) == 56);
static_assert(sizeof(agnocast_take) == 72);
static_assert(sizeof(agnocast_release) == 24);
static_assert(sizeof(agnocast_topic_summary) == 400);
static_assert(sizeof(agnocast_list_topics) == 24);
static_assert(sizeof(agnocast_publisher_info) == 168);
static_assert(sizeof(agnocast_subscriber_info) == 176);
static_assert(sizeof(agnocast_topic_info) == 432);
static_assert(sizeof(agnocast_topic_schema) == 272);
static_assert(sizeof(agnocast_process_info) == 32);
static_assert(sizeof(agnocast_list_processes) == 24);
static_assert(sizeof(agnocast_exit_record) == 272);
static_assert(sizeof(agnocast_shed) == 8);
static_assert(sizeof(agnocast_principal) == 8);
static_assert(sizeof(agnocast_policy_rule) == 280);
static_assert(sizeof(agnocast_policy) == 32);
static_assert(sizeof(agnocast_notify_failed) == 16);

void* const kBadPtr = reinterpret_cast<void*>(8);

class Device : public ::testing::Test {
 protected:
  void SetUp() override {
    dev = open_device();
    ASSERT_GE(dev, 0) << strerror(errno);
  }
  void TearDown() override {
    agnocast_policy none{};  // a failed policy test must not hold back the others
    ioc(dev, AGNOCAST_IOC_SET_POLICY, &none);
    reg.drop();
    close(dev);
  }
  void registered() { ASSERT_EQ(reg.full(dev), 0); }

  int dev = -1;
  Registration reg;
};

TEST(Abi, VersionMacrosMatchModuleVersion) {
  EXPECT_EQ(AGNOCAST_VERSION_MAJOR, 0);
  EXPECT_EQ(AGNOCAST_IOC_MAGIC, 0xAC);
}

TEST_F(Device, GetVersion) {
  auto v = poisoned<agnocast_version>();
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_GET_VERSION, &v), 0);
  EXPECT_EQ(v.major, AGNOCAST_VERSION_MAJOR);
  EXPECT_EQ(v.minor, AGNOCAST_VERSION_MINOR);
  EXPECT_EQ(v.patch, AGNOCAST_VERSION_PATCH);
  EXPECT_EQ(v.reserved, 0u);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_GET_VERSION, static_cast<agnocast_version*>(kBadPtr)), -EFAULT);
}

TEST_F(Device, UnknownCommandIsEnotty) {
  int dummy = 0;
  EXPECT_EQ(ioc(dev, _IO(AGNOCAST_IOC_MAGIC, 99), &dummy), -ENOTTY);
  EXPECT_EQ(ioc(dev, _IOWR(AGNOCAST_IOC_MAGIC, 1, int), &dummy), -ENOTTY);
  EXPECT_EQ(ioc(dev, _IOR('x', 0, agnocast_version), &dummy), -ENOTTY);
}

TEST_F(Device, RegisterReservesSlotAndRepeats) {
  auto r = poisoned_request<agnocast_register_process>();
  r.pool_fd = -1;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), 0);
  EXPECT_EQ(r.pool_fd, -1);
  EXPECT_EQ(r.pid, getpid());
  EXPECT_GE(r.pool_addr, module_pool_base());
  EXPECT_GT(module_pool_base(), 0u);
  EXPECT_EQ(r.pool_addr % 4096, 0u);
  EXPECT_GT(r.pool_size, 0u);
  auto again = poisoned_request<agnocast_register_process>();
  again.pool_fd = -1;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &again), 0);
  EXPECT_EQ(again.pool_addr, r.pool_addr);
  EXPECT_EQ(again.pool_size, r.pool_size);
  EXPECT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), 0);
}

TEST_F(Device, RegisterErrors) {
  auto r = poisoned_request<agnocast_register_process>();
  EXPECT_EQ(
      ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, static_cast<agnocast_register_process*>(kBadPtr)),
      -EFAULT);
  // Attaching before reserving.
  r.pool_fd = 0;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -ESRCH);
  r.pool_fd = -2;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EBADF);

  ASSERT_EQ(reg.reserve(dev), 0);
  r = poisoned_request<agnocast_register_process>();
  r.pool_fd = 4000;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EBADF);

  // Not tmpfs: a pipe and a procfs file.
  int pipefd[2];
  ASSERT_EQ(pipe(pipefd), 0);
  r.pool_fd = pipefd[0];
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  close(pipefd[0]);
  close(pipefd[1]);
  int procfd = open("/proc/self/status", O_RDONLY);
  r.pool_fd = procfd;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  close(procfd);

  // Too small.
  int small = memfd_create("small", MFD_CLOEXEC);
  ASSERT_EQ(ftruncate(small, static_cast<off_t>(reg.size - 4096)), 0);
  r.pool_fd = small;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  close(small);

  // Not readable through the given descriptor.
  int full = memfd_create("wronly", MFD_CLOEXEC);
  ASSERT_EQ(ftruncate(full, static_cast<off_t>(reg.size)), 0);
  std::string path = "/proc/self/fd/" + std::to_string(full);
  int wronly = open(path.c_str(), O_WRONLY);
  ASSERT_GE(wronly, 0);
  r.pool_fd = wronly;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  close(wronly);
  close(full);

  // A pool without every seal of AGNOCAST_POOL_SEALS could be written by
  // others: -EPERM, whichever seal is missing.
  const unsigned int seals[] = {AGNOCAST_POOL_SEALS, F_SEAL_SHRINK, F_SEAL_GROW,
                                F_SEAL_FUTURE_WRITE, F_SEAL_SEAL};
  for (unsigned int missing : seals) {
    int unsealed = memfd_create("unsealed", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    ASSERT_EQ(ftruncate(unsealed, static_cast<off_t>(reg.size)), 0);
    const unsigned int present = AGNOCAST_POOL_SEALS & ~missing;
    if (present) {
      ASSERT_EQ(fcntl(unsealed, F_ADD_SEALS, present), 0);
    }
    r.pool_fd = unsealed;
    EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EPERM) << "seals " << present;
    close(unsealed);
  }
  // F_SEAL_WRITE (no writable mapping at all) may stand for F_SEAL_FUTURE_WRITE.
  int write_sealed = memfd_create("write-sealed", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  ASSERT_EQ(ftruncate(write_sealed, static_cast<off_t>(reg.size)), 0);
  ASSERT_EQ(
      fcntl(write_sealed, F_ADD_SEALS, (AGNOCAST_POOL_SEALS & ~F_SEAL_FUTURE_WRITE) | F_SEAL_WRITE),
      0);
  Registration other;
  EXPECT_EQ(in_child([&] {
              if (other.reserve(open_device())) return 10;
              agnocast_register_process attach = poisoned_request<agnocast_register_process>();
              attach.pool_fd = write_sealed;
              return ioc(other.dev, AGNOCAST_IOC_REGISTER_PROCESS, &attach) == 0 ? 0 : 11;
            }),
            0);
  close(write_sealed);

  ASSERT_EQ(reg.attach(), 0);
  r = poisoned_request<agnocast_register_process>();
  r.pool_fd = reg.memfd;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EBUSY);
  // Step one after attaching still reports the slot.
  r = poisoned_request<agnocast_register_process>();
  r.pool_fd = -1;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), 0);
  EXPECT_EQ(r.pool_addr, reg.addr);
  EXPECT_EQ(r.pid, getpid());
}

TEST_F(Device, Unregister) {
  EXPECT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), -ESRCH);
  registered();
  EXPECT_TRUE(process_listed(dev, getpid()));
  EXPECT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), 0);
  EXPECT_FALSE(process_listed(dev, getpid()));
  EXPECT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), -ESRCH);
  Endpoint ep;
  EXPECT_EQ(add_publisher(dev, "/t", 1, &ep), -ESRCH);
}

TEST_F(Device, EndpointCommandsNeedRegistration) {
  Endpoint ep;
  EXPECT_EQ(add_publisher(dev, "/t", 1, &ep), -ESRCH);
  EXPECT_EQ(add_subscriber(dev, "/t", 1, &ep), -ESRCH);
  agnocast_remove_endpoint rm{1, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ESRCH);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), -ESRCH);
  EXPECT_EQ(publish(dev, {1, 0}, 0x40000000000ull), -ESRCH);
  auto rc = poisoned<agnocast_reclaim>();
  rc.reserved = 0;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), -ESRCH);
  ReceiveResult rr;
  EXPECT_EQ(receive(dev, {1, 0}, &rr), -ESRCH);
  auto take = poisoned_request<agnocast_take>();
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), -ESRCH);
  EXPECT_EQ(release(dev, {1, 0}, 0), -ESRCH);
}

// NOTIFY_FAILED's arguments, each refusal with the errno the UAPI header names.
TEST_F(Device, NotifyFailedErrors) {
  const auto notify_failed = [&](Endpoint pub, uint32_t subscriber_id, uint32_t reserved = 0) {
    auto arg = poisoned<agnocast_notify_failed>();
    arg.topic_handle = pub.handle;
    arg.publisher_id = pub.id;
    arg.subscriber_id = subscriber_id;
    arg.reserved = reserved;
    return ioc(dev, AGNOCAST_IOC_NOTIFY_FAILED, &arg);
  };
  EXPECT_EQ(notify_failed({1, 0}, 1), -ESRCH);
  registered();
  Endpoint pub, sub, gone;
  ASSERT_EQ(add_publisher(dev, "/nf", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/nf", 1, &sub), 0);
  ASSERT_EQ(add_subscriber(dev, "/nf", 1, &gone), 0);
  agnocast_remove_endpoint rm{gone.handle, gone.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);

  EXPECT_EQ(notify_failed(pub, sub.id), 0);
  EXPECT_EQ(notify_failed(pub, sub.id, 1), -EINVAL);
  EXPECT_EQ(notify_failed({pub.handle, pub.id + 5}, sub.id), -ENOENT);
  EXPECT_EQ(notify_failed({pub.handle + 1000, pub.id}, sub.id), -ENOENT);
  EXPECT_EQ(notify_failed({sub.handle, sub.id}, sub.id), -ENOENT);  // not a publisher
  EXPECT_EQ(notify_failed(pub, gone.id), -ENOENT);
  EXPECT_EQ(notify_failed(pub, pub.id), -ENOENT);  // not a subscriber
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_NOTIFY_FAILED, static_cast<agnocast_notify_failed*>(kBadPtr)),
            -EFAULT);
  EXPECT_EQ(in_child([&] {
              Registration other;
              if (other.full(open_device())) return 10;
              auto arg = poisoned<agnocast_notify_failed>();
              arg.topic_handle = pub.handle;
              arg.publisher_id = pub.id;
              arg.subscriber_id = sub.id;
              arg.reserved = 0;
              return ioc(other.dev, AGNOCAST_IOC_NOTIFY_FAILED, &arg) == -EPERM ? 0 : 11;
            }),
            0);
}

TEST_F(Device, AddEndpointsShareIdsPerTopic) {
  registered();
  auto ep = endpoint("/chatter", 10, 0, "talker");
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), 0);
  EXPECT_EQ(ep.id, 0u);
  EXPECT_GT(ep.topic_handle, 0u);
  EXPECT_EQ(ep.depth, 10u);
  uint32_t handle = ep.topic_handle;
  ep = endpoint("/chatter", 3, AGNOCAST_TRANSIENT_LOCAL, "listener");
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), 0);
  EXPECT_EQ(ep.id, 1u);
  EXPECT_EQ(ep.topic_handle, handle);
  ep = endpoint("/chatter", 1, AGNOCAST_POLLING, "");
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), 0);
  EXPECT_EQ(ep.id, 2u);

  agnocast_topic_info info;
  std::vector<agnocast_publisher_info> pubs;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/chatter", &info, &pubs, &subs), 0);
  EXPECT_EQ(info.publisher_total, 1u);
  EXPECT_EQ(info.subscriber_total, 2u);
  EXPECT_EQ(info.entries, 0u);
  EXPECT_STREQ(info.type_name, "");
  EXPECT_EQ(info.type_hash, 0u);
  EXPECT_EQ(info.schema_size, 0u);
  ASSERT_EQ(pubs.size(), 1u);
  EXPECT_STREQ(pubs[0].node, "talker");
  EXPECT_EQ(pubs[0].pid, getpid());
  EXPECT_EQ(pubs[0].depth, 10u);
  EXPECT_EQ(pubs[0].flags, 0u);
  EXPECT_EQ(pubs[0].published, 0u);
  EXPECT_EQ(pubs[0].window, 0u);
  EXPECT_EQ(pubs[0].uid, 0u);
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0].id, 1u);
  EXPECT_STREQ(subs[0].node, "listener");
  EXPECT_EQ(subs[0].flags, static_cast<uint32_t>(AGNOCAST_TRANSIENT_LOCAL));
  EXPECT_EQ(subs[1].id, 2u);
  EXPECT_EQ(subs[1].flags, static_cast<uint32_t>(AGNOCAST_POLLING));
  EXPECT_EQ(subs[1].unreceived, 0u);
  EXPECT_EQ(subs[1].held, 0u);
  EXPECT_EQ(subs[1].dropped, 0u);
}

// A topic's type is fixed by the endpoint that creates it; later endpoints
// must name the same type, and the first schema brought stays for tools.
TEST_F(Device, TopicTypeIsFixedByItsFirstEndpoint) {
  registered();
  const std::vector<uint8_t> schema = {'A', 'G', 'S', 'C', 1, 2, 3};
  auto typed = [&](const std::string& type, uint64_t hash, const std::vector<uint8_t>* blob,
                   bool publisher) {
    agnocast_add_endpoint ep = endpoint("/typed", 4);
    std::strncpy(ep.type_name, type.c_str(), sizeof(ep.type_name) - 1);
    ep.type_hash = hash;
    if (blob) {
      ep.schema = uptr(blob->data());
      ep.schema_size = static_cast<uint32_t>(blob->size());
    }
    return ioc(dev, publisher ? AGNOCAST_IOC_ADD_PUBLISHER : AGNOCAST_IOC_ADD_SUBSCRIBER, &ep);
  };
  ASSERT_EQ(typed("pkg/msg/A", 0x1111, nullptr, false), 0);  // creates it, without a schema
  EXPECT_EQ(typed("pkg/msg/A", 0x2222, &schema, true), -EPROTOTYPE);
  EXPECT_EQ(typed("pkg/msg/B", 0x1111, &schema, true), -EPROTOTYPE);
  EXPECT_EQ(typed("", 0, nullptr, true), -EPROTOTYPE);

  agnocast_topic_schema ts = poisoned<agnocast_topic_schema>();
  std::memset(ts.name, 0, sizeof(ts.name));
  std::strcpy(ts.name, "/typed");
  std::vector<uint8_t> out(64, kPoison);
  ts.schema = uptr(out.data());
  ts.capacity = 64;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_SCHEMA, &ts), -ENODATA);
  ASSERT_EQ(typed("pkg/msg/A", 0x1111, &schema, true), 0);  // brings the schema
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_SCHEMA, &ts), 0);
  EXPECT_EQ(ts.size, schema.size());
  EXPECT_TRUE(std::equal(schema.begin(), schema.end(), out.begin()));
  EXPECT_EQ(out[schema.size()], kPoison);
  ts.capacity = 3;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_SCHEMA, &ts), -ENOSPC);
  EXPECT_EQ(ts.size, schema.size());
  ts.capacity = 64;
  ts.schema = uptr(kBadPtr);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_SCHEMA, &ts), -EFAULT);
  std::strcpy(ts.name, "/untyped");
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_SCHEMA, &ts), -ENOENT);

  agnocast_topic_info info;
  ASSERT_EQ(topic_info(dev, "/typed", &info), 0);
  EXPECT_STREQ(info.type_name, "pkg/msg/A");
  EXPECT_EQ(info.type_hash, 0x1111u);
  EXPECT_EQ(info.schema_size, schema.size());
  agnocast_topic_summary topics[4];
  agnocast_list_topics lt{uptr(topics), 4, 0, 0, 0};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), 0);
  ASSERT_EQ(lt.total, 1u);
  EXPECT_STREQ(topics[0].type_name, "pkg/msg/A");
  EXPECT_EQ(topics[0].type_hash, 0x1111u);

  // Bad type names, schema sizes and reserved fields.
  EXPECT_EQ(typed("has space", 1, nullptr, true), -EINVAL);
  EXPECT_EQ(typed("tab\t", 1, nullptr, true), -EINVAL);
  agnocast_add_endpoint ep = endpoint("/typed", 4);
  std::memset(ep.type_name, 'a', sizeof(ep.type_name));
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/typed", 4);
  ep.schema_size = AGNOCAST_SCHEMA_MAX + 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/typed", 4);
  ep.reserved = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/other", 4);
  ep.schema = uptr(kBadPtr);
  ep.schema_size = 16;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EFAULT);
  EXPECT_EQ(topic_info(dev, "/other", &info), -ENOENT);  // nothing left behind

  // Once the topic is gone, it may come back with another type.
  ASSERT_EQ(ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS), 0);
  EXPECT_EQ(in_child([&] {
              Registration r;
              if (r.reserve(dev)) return 10;
              return typed("pkg/msg/B", 0x3333, nullptr, true) == 0 ? 0 : 11;
            }),
            0);
}

TEST_F(Device, IdsNeverCollideAcrossMangledNames) {
  registered();
  Endpoint a, b, c;
  ASSERT_EQ(add_subscriber(dev, "/a/b", 1, &a), 0);
  ASSERT_EQ(add_subscriber(dev, "/a_b", 1, &b), 0);
  EXPECT_NE(a.handle, b.handle);
  EXPECT_EQ(a.id, 0u);
  EXPECT_EQ(b.id, 1u);
  // Ids are not reused after a topic goes away and comes back.
  agnocast_remove_endpoint rm{a.handle, a.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);
  rm = {b.handle, b.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);
  agnocast_topic_info info;
  EXPECT_EQ(topic_info(dev, "/a/b", &info), -ENOENT);
  ASSERT_EQ(add_subscriber(dev, "/a/b", 1, &c), 0);
  EXPECT_EQ(c.id, 2u);
}

TEST_F(Device, AddEndpointRejectsBadInput) {
  registered();
  for (const char* name :
       {"", "a", "/", "//", "//a", "/a/", "/a//b", "/a-b", "/a b", "/a.b", "/\xc3\xa9", "a/b"}) {
    auto ep = endpoint(name, 1);
    EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL) << name;
    EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), -EINVAL) << name;
  }
  auto ep = endpoint("/ok", 1);
  std::memset(ep.topic, 'a', sizeof(ep.topic));
  ep.topic[0] = '/';
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);  // unterminated
  ep = endpoint("/ok", 1, 0, "bad\x01label");
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/ok", 1, 0, "\x7f");
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), -EINVAL);
  ep = endpoint("/ok", 1);
  std::memset(ep.node, 'n', sizeof(ep.node));
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), -EINVAL);  // unterminated
  ep = endpoint("/ok", 0);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/ok", AGNOCAST_DEPTH_MAX + 1);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), -EINVAL);
  ep = endpoint("/ok", 1, 1u << 3);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_SUBSCRIBER, &ep), -EINVAL);
  ep = endpoint("/ok", 1, AGNOCAST_POLLING);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  ep = endpoint("/ok", 1, AGNOCAST_IGNORE_LOCAL);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, &ep), -EINVAL);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_ADD_PUBLISHER, static_cast<agnocast_add_endpoint*>(kBadPtr)),
            -EFAULT);
  // A 255-character name and the maximum depth are fine.
  std::string longest = "/" + std::string(254, 'x');
  Endpoint ok;
  EXPECT_EQ(add_subscriber(dev, longest, AGNOCAST_DEPTH_MAX, &ok), 0);
  // Nothing was left behind by the failures.
  agnocast_topic_info info;
  EXPECT_EQ(topic_info(dev, "/ok", &info), -ENOENT);
}

TEST_F(Device, TooManyEndpointsIsEnospc) {
  registered();
  Endpoint ep;
  // This process reaches max_endpoints_per_process (1024) with the topic's
  // maximum subscribers; other processes then meet the topic's limit.
  for (int i = 0; i < AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX; i++)
    ASSERT_EQ(add_subscriber(dev, "/crowd", 1, &ep), 0) << i;
  EXPECT_EQ(add_publisher(dev, "/elsewhere", 1, &ep), -EMFILE);
  EXPECT_EQ(in_child([] {
              Registration r;
              Endpoint e;
              int d = open_device();
              if (r.reserve(d)) return 10;
              return add_subscriber(d, "/crowd", 1, &e) == -ENOSPC ? 0 : 11;
            }),
            0);
  // A second process fills the topic's publishers while a third tries.
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  pid_t holder = fork();
  if (holder == 0) {
    Registration r;
    Endpoint e;
    int d = open_device();
    if (r.reserve(d)) _exit(10);
    for (int i = 0; i < AGNOCAST_PUBLISHERS_PER_TOPIC_MAX; i++)
      if (add_publisher(d, "/crowd", 1, &e)) _exit(11);
    (void)!write(ready[1], "r", 1);
    pause();
    _exit(0);
  }
  char c;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  EXPECT_EQ(in_child([] {
              Registration r;
              Endpoint e;
              int d = open_device();
              return !r.reserve(d) && add_publisher(d, "/crowd", 1, &e) == -ENOSPC ? 0 : 1;
            }),
            0);
  kill(holder, SIGKILL);
  waitpid(holder, nullptr, 0);
  close(ready[0]);
  close(ready[1]);
}

TEST_F(Device, RemoveEndpoint) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/rm", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/rm", 1, &sub), 0);
  agnocast_remove_endpoint rm{pub.handle + 1000, pub.id};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ENOENT);
  rm = {0xffffffffu, pub.id};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ENOENT);
  rm = {pub.handle, 77};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ENOENT);
  rm = {sub.handle, sub.id};  // a subscriber id is not a publisher
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ENOENT);
  rm = {pub.handle, pub.id};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), -ENOENT);
  EXPECT_EQ(
      ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, static_cast<agnocast_remove_endpoint*>(kBadPtr)),
      -EFAULT);
  // Another process may not remove ours.
  EXPECT_EQ(in_child([&] {
              Registration child;
              if (child.full(dev)) return 10;
              agnocast_remove_endpoint r{pub.handle, pub.id};
              if (ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &r) != -EPERM) return 11;
              r = {sub.handle, sub.id};
              if (ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &r) != -EPERM) return 12;
              if (publish(dev, pub, child.addr) != -EPERM) return 13;
              ReceiveResult rr;
              if (receive(dev, sub, &rr) != -EPERM) return 14;
              if (release(dev, sub, 0) != -EPERM) return 15;
              return 0;
            }),
            0);
  rm = {pub.handle, pub.id};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), 0);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), -ENOENT);
  rm = {sub.handle, sub.id};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);
  // The topic is gone with its last endpoint, and so is its handle.
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), -ENOENT);
  agnocast_topic_info info;
  EXPECT_EQ(topic_info(dev, "/rm", &info), -ENOENT);
  drain_exit_records(dev);
}

// The data path finds the endpoints a process used last without a lookup;
// one removed must be refused at once, and an id given again must name the
// new endpoint, not the old one.
TEST_F(Device, RemovedEndpointIsRefusedRightAfterUse) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/recent", 2, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/recent", 2, &sub), 0);
  Endpoint keep;  // keeps the topic, and its handle, alive
  ASSERT_EQ(add_subscriber(dev, "/recent", 2, &keep), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 64), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  agnocast_remove_endpoint rm{pub.handle, pub.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_PUBLISHER, &rm), 0);
  rm = {sub.handle, sub.id};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REMOVE_SUBSCRIBER, &rm), 0);
  EXPECT_EQ(publish(dev, pub, reg.addr + 128), -ENOENT);
  EXPECT_EQ(receive(dev, sub, &rr), -ENOENT);
  EXPECT_EQ(release(dev, sub, 0), -ENOENT);

  // New endpoints of the same topic, which may get the old ids back.
  Endpoint pub2, sub2;
  ASSERT_EQ(add_subscriber(dev, "/recent", 2, &sub2), 0);
  ASSERT_EQ(add_publisher(dev, "/recent", 2, &pub2), 0);
  if (sub2.id == pub.id) {
    EXPECT_EQ(publish(dev, pub, reg.addr + 128), -ENOENT);
  }
  if (pub2.id == sub.id) {
    EXPECT_EQ(receive(dev, sub, &rr), -ENOENT);
  }
  PublishResult res;
  ASSERT_EQ(publish(dev, pub2, reg.addr + 192, &res), 0);
  ASSERT_EQ(receive(dev, sub2, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_EQ(rr.entries[0].entry_id, res.entry_id);
  EXPECT_EQ(rr.entries[0].publisher_id, pub2.id);
  drain_exit_records(dev);
}

TEST_F(Device, PublishReceiveRelease) {
  registered();
  Endpoint pub, cb, poll;
  ASSERT_EQ(add_publisher(dev, "/pr", 2, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/pr", 2, &cb), 0);
  ASSERT_EQ(add_subscriber(dev, "/pr", 2, &poll, AGNOCAST_POLLING), 0);

  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &res), 0);
  EXPECT_EQ(res.entry_id, 0u);
  ASSERT_EQ(res.wake.size(), 1u);  // the polling subscriber is never woken
  EXPECT_EQ(res.wake[0], cb.id);
  EXPECT_TRUE(res.reclaim.empty());
  EXPECT_EQ(res.reclaim_pending, 0u);
  ASSERT_EQ(publish(dev, pub, reg.addr + 128, &res), 0);
  EXPECT_EQ(res.entry_id, 1u);

  ReceiveResult rr;
  ASSERT_EQ(receive(dev, cb, &rr, 1), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_EQ(rr.entries[0].entry_id, 0u);
  EXPECT_EQ(rr.entries[0].addr, reg.addr + 64);
  EXPECT_EQ(rr.entries[0].publisher_id, pub.id);
  EXPECT_EQ(rr.entries[0].reserved, 0u);
  EXPECT_TRUE(rr.pools.empty());  // our own pool is never handed to us
  EXPECT_EQ(rr.remaining, 1u);
  ASSERT_EQ(receive(dev, cb, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_EQ(rr.entries[0].entry_id, 1u);
  EXPECT_EQ(rr.remaining, 0u);
  ASSERT_EQ(receive(dev, cb, &rr), 0);
  EXPECT_TRUE(rr.entries.empty());

  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  std::vector<agnocast_publisher_info> pubs;
  ASSERT_EQ(topic_info(dev, "/pr", &info, &pubs, &subs), 0);
  EXPECT_EQ(info.entries, 2u);
  EXPECT_EQ(pubs[0].published, 2u);
  EXPECT_EQ(pubs[0].published_bytes, 16u);
  EXPECT_EQ(pubs[0].window, 2u);
  EXPECT_EQ(subs[0].held, 2u);
  EXPECT_EQ(subs[0].received, 2u);
  EXPECT_EQ(subs[1].unreceived, 2u);

  EXPECT_EQ(release(dev, cb, 5), -ENOENT);
  EXPECT_EQ(release(dev, poll, 0), -ENOENT);  // unreceived is not held
  EXPECT_EQ(release(dev, cb, 0), 0);
  EXPECT_EQ(release(dev, cb, 0), -ENOENT);
  EXPECT_EQ(release(dev, {cb.handle, 99}, 1), -ENOENT);
  EXPECT_EQ(release(dev, {0, cb.id}, 1), -ENOENT);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RELEASE, static_cast<agnocast_release*>(kBadPtr)), -EFAULT);

  // Entry 0 is still unreceived by the polling subscriber.  A third publish
  // pushes it out of the window of 2; the polling subscriber over its depth
  // drops it, and then nobody references it: it comes back for reclaim.
  ASSERT_EQ(publish(dev, pub, reg.addr + 192, &res), 0);
  ASSERT_EQ(res.reclaim.size(), 1u);
  EXPECT_EQ(res.reclaim[0], reg.addr + 64);
  ASSERT_EQ(topic_info(dev, "/pr", &info, &pubs, &subs), 0);
  EXPECT_EQ(subs[1].dropped, 1u);
  EXPECT_EQ(subs[1].unreceived, 2u);
}

// A subscriber with IGNORE_LOCAL never queues, wakes for or is given as
// history the entries of its own process; another process's reach it.
TEST_F(Device, IgnoreLocalSkipsOnlyTheOwnProcesssEntries) {
  registered();
  Endpoint pub, plain, ignoring, ignoring_poll, late;
  ASSERT_EQ(add_publisher(dev, "/il", 4, &pub, AGNOCAST_TRANSIENT_LOCAL), 0);
  ASSERT_EQ(add_subscriber(dev, "/il", 4, &plain), 0);
  ASSERT_EQ(add_subscriber(dev, "/il", 4, &ignoring, AGNOCAST_IGNORE_LOCAL), 0);
  ASSERT_EQ(add_subscriber(dev, "/il", 4, &ignoring_poll, AGNOCAST_IGNORE_LOCAL | AGNOCAST_POLLING),
            0);

  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &res), 0);
  ASSERT_EQ(res.wake.size(), 1u);
  EXPECT_EQ(res.wake[0], plain.id);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, ignoring, &rr), 0);
  EXPECT_TRUE(rr.entries.empty());
  ASSERT_EQ(add_subscriber(dev, "/il", 4, &late, AGNOCAST_IGNORE_LOCAL | AGNOCAST_TRANSIENT_LOCAL),
            0);

  int published[2];
  ASSERT_EQ(pipe(published), 0);
  const pid_t child = fork();
  if (child == 0) {
    const int d = open_device();
    Registration r;
    Endpoint other;
    if (r.full(d) || add_publisher(d, "/il", 4, &other)) _exit(10);
    PublishResult child_res;
    if (publish(d, other, r.addr + 64, &child_res)) _exit(11);
    // Woken: the plain and the ignoring callback subscribers of the parent.
    if (child_res.wake.size() != 3u) _exit(12);
    if (write(published[1], "x", 1) != 1) _exit(13);
    pause();
  }
  close(published[1]);
  char byte;
  ASSERT_EQ(read(published[0], &byte, 1), 1) << "the child failed";
  close(published[0]);

  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/il", &info, nullptr, &subs), 0);
  ASSERT_EQ(subs.size(), 4u);
  EXPECT_EQ(subs[0].unreceived, 2u);  // plain: both
  EXPECT_EQ(subs[1].unreceived, 1u);  // ignoring: only the child's
  EXPECT_EQ(subs[2].unreceived, 1u);
  EXPECT_EQ(subs[2].flags, static_cast<uint32_t>(AGNOCAST_IGNORE_LOCAL | AGNOCAST_POLLING));
  EXPECT_EQ(subs[3].unreceived, 1u);  // no history from its own transient-local publisher
  ASSERT_EQ(receive(dev, ignoring, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_NE(rr.entries[0].publisher_id, pub.id);
  for (const auto& grant : rr.pools) close(grant.fd);
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  ASSERT_TRUE(eventually([&] { return !process_listed(dev, child); }));
  drain_exit_records(dev);
}

// Freed entries and held records are reused (up to 16 per process), and a
// RECEIVE of up to 4 entries works on the stack: across rounds that recycle
// them, every entry still comes out whole and in order.
TEST_F(Device, ReusedBookkeepingStartsClean) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/reuse", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/reuse", 8, &sub), 0);
  uint64_t next_id = 0;
  std::vector<uint64_t> reclaimed;
  for (int round = 0; round < 4; round++) {
    PublishResult res;
    for (uint64_t i = 0; i < 8; i++) {
      ASSERT_EQ(publish(dev, pub, reg.addr + 64 * (8 * round + i), &res), 0);
      EXPECT_EQ(res.entry_id, next_id + i);
      reclaimed.insert(reclaimed.end(), res.reclaim.begin(), res.reclaim.end());
    }
    // Alternate a small receive (stack) with a large one (allocated).
    const uint32_t first = round % 2 ? 3 : 64;
    ReceiveResult rr, rest;
    ASSERT_EQ(receive(dev, sub, &rr, first), 0);
    ASSERT_EQ(rr.entries.size(), std::min<uint32_t>(first, 8));
    EXPECT_EQ(rr.remaining, 8 - rr.entries.size());
    ASSERT_EQ(receive(dev, sub, &rest), 0);
    EXPECT_EQ(rest.remaining, 0u);
    rr.entries.insert(rr.entries.end(), rest.entries.begin(), rest.entries.end());
    ASSERT_EQ(rr.entries.size(), 8u);
    for (uint64_t i = 0; i < 8; i++) {
      EXPECT_EQ(rr.entries[i].entry_id, next_id + i);
      EXPECT_EQ(rr.entries[i].addr, reg.addr + 64 * (8 * round + i));
      EXPECT_EQ(rr.entries[i].publisher_id, pub.id);
      EXPECT_EQ(rr.entries[i].reserved, 0u);
    }
    agnocast_topic_info info;
    std::vector<agnocast_subscriber_info> subs;
    ASSERT_EQ(topic_info(dev, "/reuse", &info, nullptr, &subs), 0);
    EXPECT_EQ(subs[0].held, 8u);
    EXPECT_EQ(subs[0].unreceived, 0u);
    for (const auto& entry : rr.entries) ASSERT_EQ(release(dev, sub, entry.entry_id), 0);
    ASSERT_EQ(topic_info(dev, "/reuse", &info, nullptr, &subs), 0);
    EXPECT_EQ(subs[0].held, 0u);
    EXPECT_EQ(info.entries, 1u);  // the newest stays in the publisher's window of 1
    next_id += 8;
  }
  // Every entry but the newest came back for reclaim exactly once, in order.
  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr + 64 * 32, &res), 0);
  reclaimed.insert(reclaimed.end(), res.reclaim.begin(), res.reclaim.end());
  ASSERT_EQ(reclaimed.size(), 32u);
  for (uint64_t i = 0; i < 32; i++) EXPECT_EQ(reclaimed[i], reg.addr + 64 * i);
}

TEST_F(Device, PublishErrors) {
  Endpoint pub;
  // Slot reserved but no pool attached yet: -EBUSY.
  ASSERT_EQ(reg.reserve(dev), 0);
  ASSERT_EQ(add_publisher(dev, "/pe", 1, &pub), 0);
  EXPECT_EQ(publish(dev, pub, reg.addr), -EBUSY);
  ASSERT_EQ(reg.attach(), 0);

  EXPECT_EQ(publish(dev, pub, reg.addr - 1), -EFAULT);
  EXPECT_EQ(publish(dev, pub, reg.addr + reg.size), -EFAULT);
  EXPECT_EQ(publish(dev, pub, 0), -EFAULT);
  EXPECT_EQ(publish(dev, {pub.handle + 1000, pub.id}, reg.addr), -ENOENT);
  EXPECT_EQ(publish(dev, {pub.handle, pub.id + 5}, reg.addr), -ENOENT);

  auto arg = poisoned<agnocast_publish>();
  arg.topic_handle = pub.handle;
  arg.publisher_id = pub.id;
  arg.addr = reg.addr;
  arg.reserved = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), -EINVAL);
  arg.reserved = 0;
  arg.flags = 1U << 7;  // unknown
  arg.to_subscriber = 0;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), -EINVAL);
  arg.flags = AGNOCAST_PUBLISH_NO_DROP;
  arg.to_subscriber = 1;  // without TO_ONE
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), -EINVAL);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, static_cast<agnocast_publish*>(kBadPtr)), -EFAULT);

  Endpoint s1, s2, sp;
  ASSERT_EQ(add_subscriber(dev, "/pe", 1, &s1), 0);
  ASSERT_EQ(add_subscriber(dev, "/pe", 1, &s2), 0);
  ASSERT_EQ(add_subscriber(dev, "/pe", 1, &sp, AGNOCAST_POLLING), 0);
  uint32_t wake[2];
  arg = poisoned<agnocast_publish>();
  arg.topic_handle = pub.handle;
  arg.publisher_id = pub.id;
  arg.addr = reg.addr;
  arg.bytes = 1;
  arg.wake_ids = uptr(wake);
  arg.wake_capacity = 1;
  arg.reclaim = 0;
  arg.reclaim_capacity = 0;
  arg.flags = 0;
  arg.to_subscriber = 0;
  arg.reserved = 0;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), -ENOBUFS);
  arg.wake_ids = uptr(kBadPtr);
  arg.wake_capacity = 2;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), -EFAULT);
  agnocast_topic_info info;
  ASSERT_EQ(topic_info(dev, "/pe", &info), 0);
  EXPECT_EQ(info.entries, 0u);  // failed publishes leave nothing
  arg.wake_ids = uptr(wake);
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, &arg), 0);
  EXPECT_EQ(arg.entry_id, 0u);
  EXPECT_EQ(arg.wake_count, 2u);
  EXPECT_EQ(arg.reclaim_count, 0u);
  EXPECT_EQ(arg.reclaim_pending, 0u);
  EXPECT_EQ(arg.reserved, 0u);
  EXPECT_EQ(wake[0], s1.id);
  EXPECT_EQ(wake[1], s2.id);
}

static std::vector<uint32_t> unreceived_by_subscriber(int dev, const char* topic) {
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  if (topic_info(dev, topic, &info, nullptr, &subs)) return {};
  std::vector<uint32_t> unreceived;
  for (const auto& sub : subs) unreceived.push_back(sub.unreceived);
  return unreceived;
}

// A response goes to the one client that asked: the others are neither
// given the entry nor woken, and one slot of wake_ids is enough.
TEST_F(Device, PublishToOneReachesThatSubscriberOnly) {
  registered();
  Endpoint pub, a, b, polling, ignoring;
  ASSERT_EQ(add_publisher(dev, "/to_one", 2, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/to_one", 4, &a), 0);
  ASSERT_EQ(add_subscriber(dev, "/to_one", 4, &b), 0);
  ASSERT_EQ(add_subscriber(dev, "/to_one", 4, &polling, AGNOCAST_POLLING), 0);
  ASSERT_EQ(add_subscriber(dev, "/to_one", 4, &ignoring, AGNOCAST_IGNORE_LOCAL), 0);

  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &res, 64, AGNOCAST_PUBLISH_TO_ONE, b.id), 0);
  ASSERT_EQ(res.wake.size(), 1u);
  EXPECT_EQ(res.wake[0], b.id);
  EXPECT_EQ(unreceived_by_subscriber(dev, "/to_one"), (std::vector<uint32_t>{0, 1, 0, 0}));
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, a, &rr), 0);
  EXPECT_TRUE(rr.entries.empty());
  ASSERT_EQ(receive(dev, b, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_EQ(rr.entries[0].entry_id, res.entry_id);
  EXPECT_EQ(release(dev, b, res.entry_id), 0);

  // A polling subscriber is given it, never woken.
  ASSERT_EQ(publish(dev, pub, reg.addr + 128, &res, 64, AGNOCAST_PUBLISH_TO_ONE, polling.id), 0);
  EXPECT_TRUE(res.wake.empty());
  EXPECT_EQ(unreceived_by_subscriber(dev, "/to_one"), (std::vector<uint32_t>{0, 0, 1, 0}));

  // Gone, a publisher, or ignoring the publisher's process: nothing published.
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_TO_ONE, 9999), -ENXIO);
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_TO_ONE, pub.id),
            -ENXIO);
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_TO_ONE, ignoring.id),
            -ENXIO);
  agnocast_topic_info info;
  ASSERT_EQ(topic_info(dev, "/to_one", &info), 0);
  EXPECT_EQ(info.entries, 2u);

  // A transient-local publisher's window would reach late subscribers.
  Endpoint latched;
  ASSERT_EQ(add_publisher(dev, "/to_one", 2, &latched, AGNOCAST_TRANSIENT_LOCAL), 0);
  EXPECT_EQ(publish(dev, latched, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_TO_ONE, a.id),
            -EINVAL);
}

// A request is refused rather than dropping an older one, and refused when
// nobody would get it; a refusal changes nothing.
TEST_F(Device, PublishNoDropRefusesWhenAReceiverIsFullOrThereIsNone) {
  registered();
  Endpoint pub, server, other;
  ASSERT_EQ(add_publisher(dev, "/no_drop", 1, &pub), 0);
  EXPECT_EQ(publish(dev, pub, reg.addr + 64, nullptr, 64, AGNOCAST_PUBLISH_NO_DROP), -EPIPE);
  ASSERT_EQ(add_subscriber(dev, "/no_drop", 2, &server), 0);
  ASSERT_EQ(add_subscriber(dev, "/no_drop", 1, &other), 0);
  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &res, 64,
                    AGNOCAST_PUBLISH_NO_DROP | AGNOCAST_PUBLISH_TO_ONE, server.id),
            0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 128, &res, 64,
                    AGNOCAST_PUBLISH_NO_DROP | AGNOCAST_PUBLISH_TO_ONE, server.id),
            0);
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64,
                    AGNOCAST_PUBLISH_NO_DROP | AGNOCAST_PUBLISH_TO_ONE, server.id),
            -EAGAIN);
  // To everyone: the full one refuses it for all.
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_NO_DROP), -EAGAIN);
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/no_drop", &info, nullptr, &subs), 0);
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0].unreceived, 2u);
  EXPECT_EQ(subs[0].dropped, 0u);
  EXPECT_EQ(subs[1].unreceived, 0u);
  EXPECT_EQ(info.entries, 2u);

  // Once it receives, there is room again.
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, server, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 2u);
  EXPECT_EQ(publish(dev, pub, reg.addr + 192, nullptr, 64, AGNOCAST_PUBLISH_NO_DROP), 0);
  // Without the flag, a full subscriber drops its oldest as before.
  EXPECT_EQ(publish(dev, pub, reg.addr + 256, nullptr, 64), 0);
  ASSERT_EQ(topic_info(dev, "/no_drop", &info, nullptr, &subs), 0);
  EXPECT_EQ(subs[1].dropped, 1u);
}

TEST_F(Device, Reclaim) {
  registered();
  Endpoint pub;
  ASSERT_EQ(add_publisher(dev, "/rc", 1, &pub), 0);
  PublishResult res;
  for (int i = 0; i < 4; i++) ASSERT_EQ(publish(dev, pub, reg.addr + 8 * i, &res, 0), 0);
  EXPECT_TRUE(res.reclaim.empty());
  EXPECT_EQ(res.reclaim_pending, 3u);

  auto rc = poisoned<agnocast_reclaim>();
  rc.reserved = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), -EINVAL);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, static_cast<agnocast_reclaim*>(kBadPtr)), -EFAULT);
  rc.reserved = 0;
  rc.reclaim = uptr(kBadPtr);
  rc.reclaim_capacity = 2;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), -EFAULT);  // loses nothing

  uint64_t addrs[3];
  std::memset(addrs, kPoison, sizeof(addrs));
  rc = poisoned<agnocast_reclaim>();
  rc.reclaim = uptr(addrs);
  rc.reclaim_capacity = 2;
  rc.reserved = 0;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), 0);
  EXPECT_EQ(rc.reclaim_count, 2u);
  EXPECT_EQ(rc.reclaim_pending, 1u);
  EXPECT_EQ(rc.reserved, 0u);
  EXPECT_EQ(addrs[0], reg.addr);
  EXPECT_EQ(addrs[1], reg.addr + 8);
  EXPECT_EQ(addrs[2], 0xA5A5A5A5A5A5A5A5ull);
  rc.reclaim_capacity = 3;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), 0);
  EXPECT_EQ(rc.reclaim_count, 1u);
  EXPECT_EQ(rc.reclaim_pending, 0u);
  EXPECT_EQ(addrs[0], reg.addr + 16);
}

// SHED answers a registered process only, into memory it can write; with
// nothing held it sheds nothing.
TEST_F(Device, ShedErrors) {
  auto arg = poisoned<agnocast_shed>();
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SHED, &arg), -ESRCH);
  registered();
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SHED, static_cast<agnocast_shed*>(kBadPtr)), -EFAULT);
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_SHED, &arg), 0);
  EXPECT_EQ(arg.shed, 0u);
  EXPECT_EQ(arg.reclaimable, 0u);
}

TEST_F(Device, ReceiveErrors) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/re", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/re", 4, &sub), 0);
  ReceiveResult rr;
  EXPECT_EQ(receive(dev, sub, &rr, 0, 1), -EINVAL);
  EXPECT_EQ(receive(dev, sub, &rr, 1, 0), -EINVAL);
  EXPECT_EQ(receive(dev, {sub.handle, pub.id}, &rr), -ENOENT);
  EXPECT_EQ(receive(dev, {sub.handle + 1000, sub.id}, &rr), -ENOENT);
  auto arg = poisoned<agnocast_receive>();
  arg.topic_handle = sub.handle;
  arg.subscriber_id = sub.id;
  arg.entry_capacity = 1;
  arg.pool_capacity = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECEIVE, &arg), -EINVAL);  // reserved poisoned
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECEIVE, static_cast<agnocast_receive*>(kBadPtr)), -EFAULT);

  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  arg.release_count = 0;
  arg.entries = uptr(kBadPtr);
  arg.pools = uptr(kBadPtr);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECEIVE, &arg), -EFAULT);
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/re", &info, nullptr, &subs), 0);
  EXPECT_EQ(subs[0].unreceived, 1u);  // a failed receive moved nothing
  EXPECT_EQ(subs[0].held, 0u);
}

TEST_F(Device, TakeNewestPassesOverOlder) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/tk", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/tk", 3, &sub, AGNOCAST_POLLING), 0);

  auto take = poisoned_request<agnocast_take>();
  take.topic_handle = sub.handle;
  take.subscriber_id = sub.id;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), 0);
  EXPECT_EQ(take.entry_count, 0u);
  EXPECT_EQ(take.pool_count, 0u);
  EXPECT_EQ(take.entry.entry_id, 0u);
  EXPECT_EQ(take.entry.addr, 0u);
  EXPECT_EQ(take.pool.fd, 0);

  PublishResult res;
  for (int i = 0; i < 3; i++) ASSERT_EQ(publish(dev, pub, reg.addr + 8 * i, &res), 0);
  take = poisoned_request<agnocast_take>();
  take.topic_handle = sub.handle;
  take.subscriber_id = sub.id;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), 0);
  EXPECT_EQ(take.entry_count, 1u);
  EXPECT_EQ(take.entry.entry_id, 2u);
  EXPECT_EQ(take.entry.addr, reg.addr + 16);
  EXPECT_EQ(take.entry.reserved, 0u);
  EXPECT_EQ(take.pool_count, 0u);

  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  ASSERT_EQ(topic_info(dev, "/tk", &info, nullptr, &subs), 0);
  EXPECT_EQ(subs[0].unreceived, 0u);
  EXPECT_EQ(subs[0].held, 1u);
  EXPECT_EQ(subs[0].dropped, 0u);  // passed over, not dropped
  EXPECT_EQ(info.entries, 1u);

  auto rc = poisoned<agnocast_reclaim>();
  uint64_t addrs[4];
  rc.reclaim = uptr(addrs);
  rc.reclaim_capacity = 4;
  rc.reserved = 0;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_RECLAIM, &rc), 0);
  EXPECT_EQ(rc.reclaim_count, 2u);

  take.subscriber_id = pub.id;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), -ENOENT);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, static_cast<agnocast_take*>(kBadPtr)), -EFAULT);
  EXPECT_EQ(release(dev, sub, 2), 0);
}

TEST_F(Device, TransientLocal) {
  registered();
  Endpoint tl_pub, pub, tl_sub, sub;
  ASSERT_EQ(add_publisher(dev, "/tl", 3, &tl_pub, AGNOCAST_TRANSIENT_LOCAL), 0);
  ASSERT_EQ(add_publisher(dev, "/tl", 3, &pub), 0);
  for (int i = 0; i < 5; i++) {
    ASSERT_EQ(publish(dev, tl_pub, reg.addr + 8 * i), 0);      // ids 0,2,4,6,8
    ASSERT_EQ(publish(dev, pub, reg.addr + 1024 + 8 * i), 0);  // ids 1,3,5,7,9
  }
  ASSERT_EQ(add_subscriber(dev, "/tl", 2, &tl_sub, AGNOCAST_TRANSIENT_LOCAL), 0);
  ASSERT_EQ(add_subscriber(dev, "/tl", 2, &sub), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, tl_sub, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 2u);
  EXPECT_EQ(rr.entries[0].entry_id, 6u);
  EXPECT_EQ(rr.entries[1].entry_id, 8u);
  EXPECT_EQ(rr.entries[1].publisher_id, tl_pub.id);
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  EXPECT_TRUE(rr.entries.empty());
}

TEST_F(Device, Introspection) {
  registered();
  Endpoint ep;
  ASSERT_EQ(add_publisher(dev, "/zeta", 1, &ep), 0);
  ASSERT_EQ(add_subscriber(dev, "/alpha", 1, &ep), 0);
  ASSERT_EQ(add_subscriber(dev, "/alpha", 1, &ep), 0);

  agnocast_topic_summary topics[4];
  std::memset(topics, kPoison, sizeof(topics));
  auto lt = poisoned_request<agnocast_list_topics>();
  lt.topics = uptr(topics);
  lt.capacity = 4;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), 0);
  ASSERT_EQ(lt.total, 2u);
  EXPECT_STREQ(topics[0].name, "/alpha");
  EXPECT_EQ(topics[0].publishers, 0u);
  EXPECT_EQ(topics[0].subscribers, 2u);
  EXPECT_STREQ(topics[1].name, "/zeta");
  EXPECT_EQ(topics[1].publishers, 1u);
  EXPECT_EQ(static_cast<uint8_t>(topics[2].name[0]), kPoison);
  lt.capacity = 1;
  std::memset(topics, kPoison, sizeof(topics));
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), 0);
  EXPECT_EQ(lt.total, 2u);
  EXPECT_STREQ(topics[0].name, "/alpha");
  EXPECT_EQ(static_cast<uint8_t>(topics[1].name[0]), kPoison);
  lt.capacity = 0;
  lt.topics = 0;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), 0);
  EXPECT_EQ(lt.total, 2u);
  lt.capacity = 2;
  lt.topics = uptr(kBadPtr);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), -EFAULT);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, static_cast<agnocast_list_topics*>(kBadPtr)),
            -EFAULT);

  agnocast_topic_info info;
  EXPECT_EQ(topic_info(dev, "/nope", &info), -ENOENT);
  EXPECT_EQ(topic_info(dev, "bad", &info), -EINVAL);
  info = poisoned<agnocast_topic_info>();
  std::strcpy(info.name, "/zeta");
  info.publisher_capacity = 0;
  info.subscriber_capacity = 0;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_INFO, &info), 0);  // outputs overwritten
  EXPECT_STREQ(info.type_name, "");
  EXPECT_EQ(info.schema_size, 0u);
  EXPECT_EQ(info.publisher_total, 1u);
  EXPECT_EQ(info.subscriber_total, 0u);
  std::memset(info.name, 'z', sizeof(info.name));
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TOPIC_INFO, &info), -EINVAL);

  std::vector<agnocast_process_info> procs(8);
  std::memset(procs.data(), kPoison, procs.size() * sizeof(procs[0]));
  auto lp = poisoned_request<agnocast_list_processes>();
  lp.processes = uptr(procs.data());
  lp.capacity = 8;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &lp), 0);
  bool found = false;
  for (uint32_t i = 0; i < std::min(lp.total, 8u); i++) {
    if (procs[i].pid != getpid()) continue;
    found = true;
    EXPECT_EQ(procs[i].publishers, 1u);
    EXPECT_EQ(procs[i].subscribers, 2u);
    EXPECT_EQ(procs[i].pools_mapped, 0u);
    EXPECT_EQ(procs[i].pool_addr, reg.addr);
    EXPECT_EQ(procs[i].pool_size, reg.size);
  }
  EXPECT_TRUE(found);
  lp.processes = uptr(kBadPtr);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &lp), -EFAULT);
  // Introspection needs no registration.
  EXPECT_EQ(in_child([&] {
              int d = open_device();
              agnocast_list_topics l{0, 0, 0, 0, 0};
              return ioc(d, AGNOCAST_IOC_LIST_TOPICS, &l) == 0 && l.total == 2 ? 0 : 1;
            }),
            0);
}

TEST_F(Device, ExitRecordsReadErrors) {
  drain_exit_records(dev);
  int fd = open_device(O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  agnocast_exit_record rec[2];
  EXPECT_EQ(read(fd, rec, sizeof(rec[0]) - 1), -1);
  EXPECT_EQ(errno, EINVAL);
  EXPECT_EQ(read(fd, rec, sizeof(rec)), -1);
  EXPECT_EQ(errno, EAGAIN);

  // A child that registers and dies leaves one PROCESS record.
  pid_t child = fork();
  if (child == 0) {
    Registration r;
    _exit(r.reserve(open_device()) ? 1 : 0);
  }
  int status;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_TRUE(eventually([&] { return !process_listed(dev, child); }));
  std::memset(rec, kPoison, sizeof(rec));
  ASSERT_EQ(read(fd, rec, sizeof(rec)), static_cast<ssize_t>(sizeof(rec[0])));
  EXPECT_EQ(rec[0].kind, static_cast<uint32_t>(AGNOCAST_EXIT_PROCESS));
  EXPECT_EQ(rec[0].pid, child);
  EXPECT_EQ(rec[0].subscriber_id, 0u);
  EXPECT_EQ(rec[0].reserved, 0u);
  EXPECT_EQ(rec[0].topic[0], '\0');
  EXPECT_EQ(static_cast<uint8_t>(rec[1].topic[0]), kPoison);

  // Without CAP_SYS_ADMIN at open: -EPERM.  The capability is the opener's:
  // a descriptor opened with it reads after setuid(), like a file's mode.
  EXPECT_EQ(in_child([&] {
              gid_t group = kAgnocastGroup;
              if (setgroups(1, &group) || setuid(65534)) return 10;
              int own = open_device(O_RDONLY | O_NONBLOCK);
              if (own < 0) return 11;
              agnocast_exit_record r;
              if (read(own, &r, sizeof(r)) != -1 || errno != EPERM) return 12;
              return read(fd, &r, sizeof(r)) == -1 && errno == EAGAIN ? 0 : 13;
            }),
            0);
  close(fd);
}

TEST_F(Device, ExitRecordsPollAndBlock) {
  drain_exit_records(dev);
  int fd = open_device(O_RDONLY);
  struct pollfd pfd = {fd, POLLIN, 0};
  EXPECT_EQ(poll(&pfd, 1, 0), 0);
  pid_t child = fork();
  if (child == 0) {
    Registration r;
    _exit(r.reserve(open_device()) ? 1 : 0);
  }
  EXPECT_EQ(poll(&pfd, 1, 10000), 1);
  EXPECT_TRUE(pfd.revents & POLLIN);
  agnocast_exit_record rec;
  ASSERT_EQ(read(fd, &rec, sizeof(rec)), static_cast<ssize_t>(sizeof(rec)));  // blocking
  EXPECT_EQ(rec.pid, child);
  waitpid(child, nullptr, 0);
  close(fd);
}

TEST_F(Device, PolicyReadBackAndPrivilege) {
  agnocast_policy get{};
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_GET_POLICY, &get), 0);
  EXPECT_EQ(get.flags, 0u);
  ASSERT_EQ(
      set_policy(
          dev,
          {{"/a", AGNOCAST_MATCH_CHILDREN, {{user_principal(7), group_principal(8)}}, std::nullopt},
           {"/b", AGNOCAST_MATCH_EXACT, std::nullopt, {{anyone_principal()}}}},
          true),
      0);
  // Read back by an unprivileged member of the group; too small: -ENOSPC with totals.
  EXPECT_EQ(
      in_child([&] {
        if (!become(kNobody, kNobody, {kAgnocastGroup})) return 10;
        int d = open_device();
        agnocast_policy p{};
        if (ioc(d, AGNOCAST_IOC_GET_POLICY, &p) != -ENOSPC) return 11;
        if (p.rule_count != 2 || p.principal_count != 3) return 12;
        std::vector<agnocast_policy_rule> rules(2);
        std::vector<agnocast_principal> principals(3);
        p.flags = 0;
        p.rules = uptr(rules.data());
        p.principals = uptr(principals.data());
        if (ioc(d, AGNOCAST_IOC_GET_POLICY, &p)) return 13;
        if (p.flags != (AGNOCAST_POLICY_PRESENT | AGNOCAST_POLICY_DEFAULT_DENY)) return 14;
        if (std::string(rules[0].prefix) != "/a" || rules[0].match != AGNOCAST_MATCH_CHILDREN ||
            rules[0].flags != AGNOCAST_RULE_PUBLISH || rules[0].publish_count != 2)
          return 15;
        if (std::string(rules[1].prefix) != "/b" || rules[1].flags != AGNOCAST_RULE_SUBSCRIBE ||
            rules[1].first_principal != 2 || rules[1].subscribe_count != 1)
          return 16;
        if (principals[0].kind != AGNOCAST_PRINCIPAL_USER || principals[0].id != 7 ||
            principals[1].kind != AGNOCAST_PRINCIPAL_GROUP || principals[1].id != 8 ||
            principals[2].kind != AGNOCAST_PRINCIPAL_ANYONE)
          return 17;
        // Not allowed to set one.
        agnocast_policy none{};
        return ioc(d, AGNOCAST_IOC_SET_POLICY, &none) == -EPERM ? 0 : 18;
      }),
      0);
  agnocast_policy none{};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &none), 0);
}

TEST_F(Device, PolicyRejectsBadInput) {
  agnocast_principal p[2] = {user_principal(1), anyone_principal()};
  agnocast_policy_rule rule{};
  std::strcpy(rule.prefix, "/ok");
  rule.flags = AGNOCAST_RULE_PUBLISH;
  rule.publish_count = 1;
  auto attempt = [&](auto change) {
    agnocast_policy_rule r = rule;
    agnocast_principal pr[2] = {p[0], p[1]};
    agnocast_policy policy{AGNOCAST_POLICY_PRESENT, 1, 2, 0, uptr(&r), uptr(pr)};
    change(policy, r, pr);
    return ioc(dev, AGNOCAST_IOC_SET_POLICY, &policy);
  };
  using P = agnocast_policy;
  using R = agnocast_policy_rule;
  using A = agnocast_principal*;
  EXPECT_EQ(attempt([](P&, R&, A) {}), 0);
  EXPECT_EQ(attempt([](P& p, R&, A) { p.reserved = 1; }), -EINVAL);
  EXPECT_EQ(attempt([](P& p, R&, A) { p.flags |= 1u << 7; }), -EINVAL);
  EXPECT_EQ(attempt([](P& p, R&, A) { p.rule_count = AGNOCAST_POLICY_RULES_MAX + 1; }), -EINVAL);
  EXPECT_EQ(attempt([](P& p, R&, A) { p.principal_count = AGNOCAST_POLICY_PRINCIPALS_MAX + 1; }),
            -EINVAL);
  EXPECT_EQ(attempt([](P& p, R&, A) { p.rules = 8; }), -EFAULT);
  EXPECT_EQ(attempt([](P&, R& r, A) { std::strcpy(r.prefix, "/bad//name"); }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { std::strcpy(r.prefix, "/trailing/"); }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { std::memset(r.prefix, 'a', sizeof(r.prefix)); }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { r.prefix[0] = '\0'; }), -EINVAL);  // exact root
  EXPECT_EQ(attempt([](P&, R& r, A) { r.match = 3; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { r.flags = 4; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { r.reserved = 1; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { r.subscribe_count = 1; }), -EINVAL);  // not flagged
  EXPECT_EQ(attempt([](P&, R& r, A) { r.first_principal = 2; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R& r, A) { r.first_principal = 0xffffffffu; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R&, A a) { a[0].kind = 9; }), -EINVAL);
  EXPECT_EQ(attempt([](P&, R&, A a) { a[1].id = 5; }), -EINVAL);            // anyone with an id
  EXPECT_EQ(attempt([](P&, R&, A a) { a[0].id = 0xffffffffu; }), -EINVAL);  // unmapped uid
  agnocast_policy removal_with_rules{0, 1, 0, 0, 0, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &removal_with_rules), -EINVAL);
  agnocast_policy get{1, 0, 0, 0, 0, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_GET_POLICY, &get), -EINVAL);
  agnocast_policy none{};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_SET_POLICY, &none), 0);
}

TEST_F(Device, MovedToAnotherIpcNamespaceIsExdev) {
  EXPECT_EQ(in_child([&] {
              Registration r;
              if (r.reserve(dev)) return 10;
              if (unshare(CLONE_NEWIPC)) return 11;
              Endpoint ep;
              if (add_publisher(dev, "/x", 1, &ep) != -EXDEV) return 12;
              if (ioc0(dev, AGNOCAST_IOC_UNREGISTER_PROCESS) != -EXDEV) return 13;
              return 0;
            }),
            0);
}

}  // namespace

// The subscriber's unreceived and held counts as TOPIC_INFO reports them.
static std::pair<uint32_t, uint32_t> unreceived_held(int dev, const char* topic) {
  agnocast_topic_info info;
  std::vector<agnocast_subscriber_info> subs;
  if (topic_info(dev, topic, &info, nullptr, &subs) || subs.empty()) return {~0u, ~0u};
  return {subs[0].unreceived, subs[0].held};
}

TEST_F(Device, ReleaseTakesAListAllOrNothing) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/rl", 8, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/rl", 8, &sub), 0);
  for (int i = 0; i < 4; i++) ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 4u);
  EXPECT_EQ(unreceived_held(dev, "/rl"), std::make_pair(0u, 4u));

  // One id not held, or one listed twice: nothing is released.
  EXPECT_EQ(release_list(dev, sub, {0, 1, 99}), -ENOENT);
  EXPECT_EQ(release_list(dev, sub, {2, 2}), -ENOENT);
  EXPECT_EQ(unreceived_held(dev, "/rl"), std::make_pair(0u, 4u));
  EXPECT_EQ(release_list(dev, sub, {}), -EINVAL);
  std::vector<uint64_t> too_many(AGNOCAST_RELEASE_MAX + 1, 0);
  EXPECT_EQ(release_list(dev, sub, too_many), -EINVAL);
  uint64_t id = 0;
  agnocast_release bad_list{sub.handle, sub.id, uptr(kBadPtr), 1, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RELEASE, &bad_list), -EFAULT);
  agnocast_release flagged{sub.handle, sub.id, uptr(&id), 1, 1};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RELEASE, &flagged), -EINVAL);
  EXPECT_EQ(unreceived_held(dev, "/rl"), std::make_pair(0u, 4u));

  // Out of receive order, all at once.
  EXPECT_EQ(release_list(dev, sub, {3, 0, 2}), 0);
  EXPECT_EQ(unreceived_held(dev, "/rl"), std::make_pair(0u, 1u));
  EXPECT_EQ(release(dev, sub, 0), -ENOENT);
  EXPECT_EQ(release(dev, sub, 1), 0);
  EXPECT_EQ(unreceived_held(dev, "/rl"), std::make_pair(0u, 0u));
}

// RECEIVE with the ids to release: a subscriber's steady state needs no RELEASE.
static int receive_releasing(int dev, Endpoint sub, const std::vector<uint64_t>& release_ids,
                             std::vector<agnocast_entry>* got, uint64_t release_ptr = 0) {
  std::vector<agnocast_entry> entries(8);
  std::vector<agnocast_pool> pools(4);
  agnocast_receive arg{};
  arg.topic_handle = sub.handle;
  arg.subscriber_id = sub.id;
  arg.entries = uptr(entries.data());
  arg.pools = uptr(pools.data());
  arg.entry_capacity = 8;
  arg.pool_capacity = 4;
  arg.release_ids = release_ptr ? release_ptr : uptr(release_ids.data());
  arg.release_count = static_cast<uint32_t>(release_ids.size());
  int ret = ioc(dev, AGNOCAST_IOC_RECEIVE, &arg);
  if (!ret && got) got->assign(entries.begin(), entries.begin() + arg.entry_count);
  return ret;
}

TEST_F(Device, ReceiveReleasesTheListedEntriesFirst) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/rr", 8, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/rr", 8, &sub), 0);
  std::vector<agnocast_entry> got;
  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  ASSERT_EQ(receive_releasing(dev, sub, {}, &got), 0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].entry_id, 0u);

  // Steady state: each receive drops what the previous one delivered.
  for (uint64_t i = 1; i < 5; i++) {
    ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i), 0);
    ASSERT_EQ(receive_releasing(dev, sub, {i - 1}, &got), 0);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].entry_id, i);
    EXPECT_EQ(unreceived_held(dev, "/rr"), std::make_pair(0u, 1u));
  }
  // Nothing to receive: the release still happens.
  ASSERT_EQ(receive_releasing(dev, sub, {4}, &got), 0);
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(unreceived_held(dev, "/rr"), std::make_pair(0u, 0u));

  // A listed id not held: nothing released, nothing received.
  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 64), 0);
  ASSERT_EQ(receive_releasing(dev, sub, {}, &got), 0);
  ASSERT_EQ(got.size(), 2u);
  ASSERT_EQ(publish(dev, pub, reg.addr + 128), 0);
  EXPECT_EQ(receive_releasing(dev, sub, {got[0].entry_id, 1234}, nullptr), -ENOENT);
  EXPECT_EQ(unreceived_held(dev, "/rr"), std::make_pair(1u, 2u));
  EXPECT_EQ(receive_releasing(dev, sub, {got[0].entry_id}, nullptr, uptr(kBadPtr)), -EFAULT);
  EXPECT_EQ(unreceived_held(dev, "/rr"), std::make_pair(1u, 2u));
  std::vector<uint64_t> too_many(AGNOCAST_RELEASE_MAX + 1, 0);
  EXPECT_EQ(receive_releasing(dev, sub, too_many, nullptr), -EINVAL);
  EXPECT_EQ(receive_releasing(dev, sub, {got[0].entry_id, got[1].entry_id}, &got), 0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(unreceived_held(dev, "/rr"), std::make_pair(0u, 1u));
}

// Held entries outgrow the room a subscriber starts with (twice its depth)
// and are found again by id, released in any order and in any grouping.
TEST_F(Device, HeldEntriesOutgrowTheirRoomAndReleaseInAnyOrder) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/hg", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/hg", 1, &sub), 0);
  std::vector<uint64_t> ids;
  for (int i = 0; i < 100; i++) {
    ASSERT_EQ(publish(dev, pub, reg.addr + 64 * i), 0);
    ReceiveResult rr;
    ASSERT_EQ(receive(dev, sub, &rr), 0);
    ASSERT_EQ(rr.entries.size(), 1u);
    ASSERT_EQ(rr.entries[0].addr, reg.addr + 64 * i);
    ids.push_back(rr.entries[0].entry_id);
  }
  EXPECT_EQ(unreceived_held(dev, "/hg"), std::make_pair(0u, 100u));

  // A duplicate or a stranger anywhere in the list: nothing released.
  EXPECT_EQ(release_list(dev, sub, {ids[99], ids[0], ids[50], ids[0]}), -ENOENT);
  EXPECT_EQ(release_list(dev, sub, {ids[10], ids[99] + 1}), -ENOENT);
  EXPECT_EQ(unreceived_held(dev, "/hg"), std::make_pair(0u, 100u));

  // Every third, newest first.
  std::vector<uint64_t> thirds;
  for (int i = 99; i >= 0; i -= 3) thirds.push_back(ids[i]);
  ASSERT_LE(thirds.size(), size_t{AGNOCAST_RELEASE_MAX});
  EXPECT_EQ(release_list(dev, sub, thirds), 0);
  const uint32_t left = 100 - static_cast<uint32_t>(thirds.size());
  EXPECT_EQ(unreceived_held(dev, "/hg"), std::make_pair(0u, left));
  for (uint64_t id : thirds) EXPECT_EQ(release(dev, sub, id), -ENOENT) << id;

  // The rest one by one, from the middle outwards; each exactly once.
  std::vector<uint64_t> rest;
  for (int i = 0; i < 100; i++) {
    if ((99 - i) % 3) rest.push_back(ids[i]);
  }
  ASSERT_EQ(rest.size(), left);
  size_t lo = rest.size() / 2, hi = lo + 1;
  while (lo > 0 || hi <= rest.size()) {
    if (lo > 0) {
      --lo;
      EXPECT_EQ(release(dev, sub, rest[lo]), 0) << rest[lo];
      EXPECT_EQ(release(dev, sub, rest[lo]), -ENOENT) << rest[lo];
    }
    if (hi <= rest.size()) {
      EXPECT_EQ(release(dev, sub, rest[hi - 1]), 0) << rest[hi - 1];
      ++hi;
    }
  }
  EXPECT_EQ(unreceived_held(dev, "/hg"), std::make_pair(0u, 0u));

  // Held again after all that: the room is reused.
  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 1u);
  EXPECT_EQ(unreceived_held(dev, "/hg"), std::make_pair(0u, 1u));
  EXPECT_EQ(release(dev, sub, rr.entries[0].entry_id), 0);
}

// Outputs are probed one byte per page: a buffer whose last page is
// read-only fails with -EFAULT before anything is received.
TEST_F(Device, ReceiveIntoABufferEndingReadOnlyReceivesNothing) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/ro", 4, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/ro", 4, &sub), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr), 0);
  const long page = sysconf(_SC_PAGESIZE);
  auto* area = static_cast<char*>(
      mmap(nullptr, 2 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(area, MAP_FAILED);
  // The first entry fits in the writable page; the buffer's end does not.
  const size_t capacity = 4;
  char* entries = area + page - sizeof(agnocast_entry);
  std::memset(entries, 0x5a, sizeof(agnocast_entry));
  ASSERT_EQ(mprotect(area + page, page, PROT_READ), 0);
  agnocast_pool pools[2];
  agnocast_receive arg{};
  arg.topic_handle = sub.handle;
  arg.subscriber_id = sub.id;
  arg.entries = uptr(entries);
  arg.entry_capacity = capacity;
  arg.pools = uptr(pools);
  arg.pool_capacity = 2;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECEIVE, &arg), -EFAULT);
  EXPECT_EQ(unreceived_held(dev, "/ro"), std::make_pair(1u, 0u));
  // The probe wrote back what was there.
  for (size_t i = 0; i < sizeof(agnocast_entry); i++)
    EXPECT_EQ(static_cast<unsigned char>(entries[i]), 0x5a) << i;
  // One entry's room, all writable: received.
  arg.entry_capacity = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_RECEIVE, &arg), 0);
  EXPECT_EQ(arg.entry_count, 1u);
  EXPECT_EQ(unreceived_held(dev, "/ro"), std::make_pair(0u, 1u));
  munmap(area, 2 * page);
}

// The watchdog signals a process's wake eventfd under no lock: once set, it
// is never replaced, so it cannot be freed under the timer.
TEST_F(Device, WakeEventfdIsSetOnce) {
  const int first = eventfd(0, EFD_CLOEXEC), second = eventfd(0, EFD_CLOEXEC);
  ASSERT_GE(first, 0);
  ASSERT_GE(second, 0);
  agnocast_register_process r{};
  r.pool_fd = -1;
  ASSERT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), 0);  // none yet
  // TearDown unregisters.
  reg.dev = dev;
  r = {};
  r.pool_fd = -1;
  r.flags = AGNOCAST_REGISTER_WAKE_EVENTFD;
  r.wake_fd = first;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), 0);  // given on a repeat
  r.wake_fd = second;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EEXIST);
  r.wake_fd = first;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EEXIST);
  r = {};
  r.pool_fd = -1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), 0) << "a repeat without one still works";
  close(first);
  close(second);
}

TEST_F(Device, RequestFlagsAndReservedMustBeZero) {
  auto r = poisoned_request<agnocast_register_process>();
  r.pool_fd = -1;
  r.flags = 1u << 31;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  r.flags = 0;
  r.wake_fd = 1;  // a wake_fd without its flag
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  r.flags = AGNOCAST_REGISTER_WAKE_EVENTFD;
  r.wake_fd = -1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EBADF);
  r.wake_fd = dev;  // open, but no eventfd
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_REGISTER_PROCESS, &r), -EINVAL);
  EXPECT_FALSE(process_listed(dev, getpid()));

  registered();
  Endpoint sub;
  ASSERT_EQ(add_subscriber(dev, "/fl", 1, &sub, AGNOCAST_POLLING), 0);
  auto take = poisoned_request<agnocast_take>();
  take.topic_handle = sub.handle;
  take.subscriber_id = sub.id;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), 0);
  take.flags = 1u << 31;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), -EINVAL);
  take.flags = 0;
  take.reserved = 1;
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_TAKE, &take), -EINVAL);

  agnocast_list_topics lt{0, 0, 0, 1, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), -EINVAL);
  lt = {0, 0, 0, 0, 1};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), -EINVAL);
  lt = {0, 0, 0, 0, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_TOPICS, &lt), 0);
  EXPECT_EQ(lt.total, 1u);
  agnocast_list_processes lp{0, 0, 0, 2, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &lp), -EINVAL);
  lp = {0, 0, 0, 0, 2};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &lp), -EINVAL);
  lp = {0, 0, 0, 0, 0};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_LIST_PROCESSES, &lp), 0);
  EXPECT_GE(lp.total, 1u);
}

// PUBLISH is all or nothing: every output is checked before the entry is
// published, so -EFAULT means nothing happened.
TEST_F(Device, PublishWithABadOutputPublishesNothing) {
  registered();
  Endpoint pub, sub;
  ASSERT_EQ(add_publisher(dev, "/aon", 1, &pub), 0);
  ASSERT_EQ(add_subscriber(dev, "/aon", 4, &sub), 0);
  // Two publishes: the first leaves the depth-1 window, reclaimable once received.
  PublishResult res;
  ASSERT_EQ(publish(dev, pub, reg.addr, &res), 0);
  ASSERT_EQ(publish(dev, pub, reg.addr + 64, &res), 0);
  ReceiveResult rr;
  ASSERT_EQ(receive(dev, sub, &rr), 0);
  ASSERT_EQ(rr.entries.size(), 2u);
  ASSERT_EQ(release(dev, sub, rr.entries[0].entry_id), 0);  // now reclaimable

  auto attempt = [&](auto change) {
    uint32_t wake[4] = {};
    uint64_t reclaim[4] = {};
    agnocast_publish arg{};
    arg.topic_handle = pub.handle;
    arg.publisher_id = pub.id;
    arg.addr = reg.addr + 128;
    arg.wake_ids = uptr(wake);
    arg.wake_capacity = 4;
    arg.reclaim = uptr(reclaim);
    arg.reclaim_capacity = 4;
    change(arg);
    return ioc(dev, AGNOCAST_IOC_PUBLISH, &arg);
  };
  auto unchanged = [&] {
    agnocast_topic_info info;
    std::vector<agnocast_publisher_info> pubs;
    std::vector<agnocast_subscriber_info> subs;
    if (topic_info(dev, "/aon", &info, &pubs, &subs)) return false;
    return info.entries == 1 && pubs[0].published == 2 && subs[0].unreceived == 0 &&
           subs[0].held == 1;
  };
  EXPECT_EQ(attempt([](agnocast_publish& a) { a.reclaim = uptr(kBadPtr); }), -EFAULT);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(attempt([](agnocast_publish& a) { a.wake_ids = uptr(kBadPtr); }), -EFAULT);
  EXPECT_TRUE(unchanged());

  // An argument the kernel can read but not write back: nothing published.
  long page = sysconf(_SC_PAGESIZE);
  void* ro = mmap(nullptr, page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(ro, MAP_FAILED);
  uint32_t wake[4];
  uint64_t reclaim[4];
  auto* arg = static_cast<agnocast_publish*>(ro);
  *arg = agnocast_publish{};
  arg->topic_handle = pub.handle;
  arg->publisher_id = pub.id;
  arg->addr = reg.addr + 128;
  arg->wake_ids = uptr(wake);
  arg->wake_capacity = 4;
  arg->reclaim = uptr(reclaim);
  arg->reclaim_capacity = 4;
  ASSERT_EQ(mprotect(ro, page, PROT_READ), 0);
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_PUBLISH, arg), -EFAULT);
  EXPECT_TRUE(unchanged());
  munmap(ro, page);

  // The reclaimable address was not lost on the way: the next publish returns it.
  ASSERT_EQ(publish(dev, pub, reg.addr + 128, &res), 0);
  ASSERT_EQ(res.reclaim.size(), 1u);
  EXPECT_EQ(res.reclaim[0], reg.addr);
}
