#include "status_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

namespace agnocastd {
namespace {

TEST(StatusJson, HasTheFieldsTheCliReads) {
  Status status;
  status.pid = 321;
  status.module_version = "0.1.0";
  status.uptime_s = 7;
  status.started_at = 1700000000;
  status.counters = {2, 3, 1};
  EXPECT_EQ(status_json(status).dump(),
            R"({"module_loaded":true,"module_version":"0.1.0","pid":321,"processes_cleaned":2,)"
            R"("queues_removed":3,"running":true,"shm_removed":1,"started_at":1700000000,)"
            R"("uptime_s":7})");
}

TEST(StatusJson, ModuleNotLoadedIsNull) {
  Status status;
  status.running = false;
  const auto json = status_json(status);
  EXPECT_FALSE(json.at("running").get<bool>());
  EXPECT_FALSE(json.at("module_loaded").get<bool>());
  EXPECT_TRUE(json.at("module_version").is_null());
}

TEST(StatusFile, ReplacedAtomicallyWithMode0644) {
  const auto directory = std::filesystem::path(::testing::TempDir()) / "agnocastd-status";
  std::filesystem::remove_all(directory);
  const auto path = (directory / "agnocastd.json").string();
  const mode_t old_umask = ::umask(077);
  write_status_file(path, {{"running", true}});
  write_status_file(path, {{"running", false}});
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
