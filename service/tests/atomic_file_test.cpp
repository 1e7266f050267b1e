#include "agnocast_service/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace agnocast_service {
namespace {

TEST(AtomicFile, ReplacedAtomicallyWithMode0644) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocast-service-atomic";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "agnocastd.json").string();
  const mode_t old_umask = ::umask(077);
  write_file_atomically(path, R"({"running":true})");
  write_file_atomically(path, R"({"running":false})");
  ::umask(old_umask);
  struct stat info {};
  ASSERT_EQ(::stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0644u);
  std::ifstream file(path);
  EXPECT_FALSE(nlohmann::json::parse(file).at("running").get<bool>());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  // The folder it made is readable by everyone, whatever the umask was.
  ASSERT_EQ(::stat(directory.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0755u);
  std::filesystem::remove_all(directory);
}

TEST(AtomicFile, ModeIsTheCallersAndTheTextWhole) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocast-service-mode";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "state").string();
  const std::string text(1 << 20, 'x');  // more than one write() may take
  write_file_atomically(path, text, 0600);
  struct stat info {};
  ASSERT_EQ(::stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  EXPECT_EQ(static_cast<std::size_t>(info.st_size), text.size());
  std::filesystem::remove_all(directory);
}

TEST(AtomicFile, AFailureThrowsAndLeavesTheOldFile) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocast-service-fail";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "status.json").string();
  write_file_atomically(path, "old");
  // A folder where the temporary file would go: it cannot be created.
  std::filesystem::create_directory(path + ".tmp");
  EXPECT_THROW(write_file_atomically(path, "new"), std::system_error);
  std::ifstream file(path);
  std::string text;
  file >> text;
  EXPECT_EQ(text, "old");
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace agnocast_service
