// Module lifetime: rmmod is refused while a process is registered or the
// device is open and works after; invalid parameters fail the load; pool_count
// bounds registrations.  Reloads $AGNOCAST_MODULE with the parameters it found
// and leaves the module loaded.
#include <sys/stat.h>
#include <sys/syscall.h>

#include <fstream>

#include "test_util.h"

using namespace agnocast_test;

namespace {

int delete_module() { return syscall(SYS_delete_module, "agnocast", O_NONBLOCK) ? -errno : 0; }

int load_module(const std::string& params) {
  const char* path = std::getenv("AGNOCAST_MODULE");
  if (!path) return -ENOENT;
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -errno;
  int ret = syscall(SYS_finit_module, fd, params.c_str(), 0) ? -errno : 0;
  close(fd);
  return ret;
}

bool device_exists() {
  struct stat st;
  return stat(AGNOCAST_DEVICE_PATH, &st) == 0 && S_ISCHR(st.st_mode);
}

std::string read_param(const char* name) {
  std::ifstream in(std::string("/sys/module/agnocast/parameters/") + name);
  std::string value;
  in >> value;
  return value;
}

// Teardown of exited processes is asynchronous: retry for a while.
int unload() {
  int ret = -EAGAIN;
  eventually([&] { return (ret = delete_module()) == 0; });
  return ret;
}

bool refused(int ret) { return ret == -EAGAIN || ret == -EBUSY; }

TEST(Module, Lifetime) {
  ASSERT_NE(std::getenv("AGNOCAST_MODULE"), nullptr);
  ASSERT_TRUE(device_exists());
  const std::string params = "pool_size=" + read_param("pool_size") +
                             " pool_count=" + read_param("pool_count") +
                             " pool_base=" + read_param("pool_base");
  std::ifstream version_file("/sys/module/agnocast/version");
  std::string version;
  version_file >> version;
  EXPECT_EQ(version, std::to_string(AGNOCAST_VERSION_MAJOR) + "." +
                         std::to_string(AGNOCAST_VERSION_MINOR) + "." +
                         std::to_string(AGNOCAST_VERSION_PATCH));

  // An open descriptor pins the module.
  int dev = open_device();
  ASSERT_GE(dev, 0);
  EXPECT_TRUE(refused(delete_module()));

  // So does a registered process that closed its descriptor.
  int sync[2];
  ASSERT_EQ(pipe(sync), 0);
  pid_t child = fork();
  if (child == 0) {
    Registration r;
    int d = open_device();
    if (r.reserve(d)) _exit(1);
    close(d);
    (void)!write(sync[1], "x", 1);
    pause();
    _exit(0);
  }
  char c;
  ASSERT_EQ(read(sync[0], &c, 1), 1);
  close(dev);
  EXPECT_TRUE(refused(delete_module()));
  EXPECT_TRUE(device_exists());

  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  ASSERT_EQ(unload(), 0);
  EXPECT_FALSE(device_exists());

  // Invalid parameters fail the load with -EINVAL.
  for (const char* bad :
       {"pool_size=0", "pool_size=4097", "pool_count=0", "pool_count=100000", "pool_base=0x1000",
        "pool_base=0x40000000001", "pool_base=0x7fff00000000",
        "pool_size=18446744073709547520 pool_count=2", "pool_size=1099511627776 pool_count=1024"}) {
    EXPECT_EQ(load_module(bad), -EINVAL) << bad;
    EXPECT_FALSE(device_exists()) << bad;
  }

  // One slot: the second process gets -ENOSPC until the first is gone.
  ASSERT_EQ(load_module("pool_count=1 pool_size=2097152"), 0);
  ASSERT_TRUE(eventually([] { return device_exists(); }));
  dev = open_device();
  ASSERT_GE(dev, 0);
  Registration first;
  ASSERT_EQ(first.full(dev), 0);
  EXPECT_EQ(first.size, 2097152u);
  EXPECT_EQ(in_child([&] {
              Registration second;
              return second.reserve(dev) == -ENOSPC ? 0 : 1;
            }),
            0);
  first.drop();
  EXPECT_EQ(in_child([&] {
              Registration second;
              return second.reserve(dev) == 0 ? 0 : 1;
            }),
            0);
  close(dev);
  ASSERT_EQ(unload(), 0);

  // Back as it was, and left loaded.
  ASSERT_EQ(load_module(params), 0);
  ASSERT_TRUE(eventually([] { return device_exists(); }));
  dev = open_device();
  agnocast_version v{};
  EXPECT_EQ(ioc(dev, AGNOCAST_IOC_GET_VERSION, &v), 0);
  close(dev);
}

}  // namespace
