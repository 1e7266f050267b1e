#include "status_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace agnocastd {
namespace {

TEST(StatusFile, ReplacedAtomicallyWithMode0644) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocastd-status";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "agnocastd.json").string();
  const mode_t old_umask = ::umask(077);
  write_status_file(path, R"({"running":true})");
  write_status_file(path, R"({"running":false})");
  ::umask(old_umask);
  struct stat info {};
  ASSERT_EQ(::stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0644u);
  std::ifstream file(path);
  EXPECT_FALSE(nlohmann::json::parse(file).at("running").get<bool>());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

}  // namespace
}  // namespace agnocastd
