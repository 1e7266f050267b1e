#include "agnocast_service/instance_lock.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

namespace agnocast_service {
namespace {

TEST(InstanceLock, OneHolderAtATimeNamedWithItsPid) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocast-service-lock";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "daemon.lock").string();
  std::optional<InstanceLock> first;
  first.emplace(path, "daemon");
  std::string pid;
  std::ifstream(path) >> pid;
  EXPECT_EQ(pid, std::to_string(::getpid()));
  struct stat info {};
  ASSERT_EQ(::stat(directory.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0755u);

  // flock locks an open file: a second open in the same process conflicts too.
  try {
    InstanceLock second(path, "daemon");
    ADD_FAILURE() << "a second lock was taken";
  } catch (const AlreadyRunning& error) {
    EXPECT_EQ(std::string(error.what()),
              "daemon is already running (pid " + std::to_string(::getpid()) + ")");
  }
  first.reset();
  EXPECT_NO_THROW(InstanceLock(path, "daemon"));
  std::filesystem::remove_all(directory);
}

TEST(InstanceLock, AnUnopenableFileIsASystemError) {
  EXPECT_THROW(InstanceLock("/proc/version/x.lock", "daemon"), std::exception);
}

}  // namespace
}  // namespace agnocast_service
