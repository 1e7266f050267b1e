#include "agnocast/status.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace agnocast {
namespace {

DaemonStatus running_daemon() {
  DaemonStatus status;
  status.pid = 321;
  status.module_version = "0.1.0";
  status.uptime_s = 7;
  status.started_at = 1700000000;
  status.counters = {2, 3, 1};
  return status;
}

// The what() of the StatusFormatError that reading text throws; empty when none.
std::string format_error_of(const std::string& text) {
  try {
    daemon_status_from_json(text);
  } catch (const StatusFormatError& error) {
    return error.what();
  }
  return "";
}

TEST(DaemonStatusJson, HasTheFieldsTheCliReads) {
  EXPECT_EQ(to_json(running_daemon()),
            R"({"module_loaded":true,"module_version":"0.1.0","pid":321,"processes_cleaned":2,)"
            R"("queues_removed":3,"running":true,"shm_removed":1,"started_at":1700000000,)"
            R"("uptime_s":7})"
            "\n");
}

TEST(DaemonStatusJson, ModuleNotLoadedIsNull) {
  DaemonStatus status;
  status.running = false;
  status.pid = 1;
  const std::string text = to_json(status);
  EXPECT_NE(text.find(R"("running":false)"), std::string::npos) << text;
  EXPECT_NE(text.find(R"("module_loaded":false)"), std::string::npos) << text;
  EXPECT_NE(text.find(R"("module_version":null)"), std::string::npos) << text;
}

TEST(DaemonStatusJson, ReadsBackWhatWasWritten) {
  const DaemonStatus loaded = running_daemon();
  EXPECT_EQ(daemon_status_from_json(to_json(loaded)), loaded);

  DaemonStatus stopped;
  stopped.running = false;
  stopped.pid = 2147483647;
  stopped.started_at = -1;
  stopped.uptime_s = 18446744073709551615u;
  EXPECT_EQ(daemon_status_from_json(to_json(stopped)), stopped);
}

TEST(DaemonStatusJson, AMissingFieldIsNamed) {
  const std::vector<std::string> fields = {
      "running",    "pid",        "module_loaded",     "module_version",
      "uptime_s",   "started_at", "processes_cleaned", "queues_removed",
      "shm_removed"};
  for (const std::string& key : fields) {
    std::string text = to_json(running_daemon());
    const std::size_t at = text.find("\"" + key + "\":");
    ASSERT_NE(at, std::string::npos) << key;
    // Rename the key: the file then lacks it.
    text.replace(at + 1, key.size(), "x" + key.substr(1));
    EXPECT_EQ(format_error_of(text), "agnocastd status file: \"" + key + "\" is missing");
  }
}

TEST(DaemonStatusJson, AFieldOfAnotherTypeIsNamedWithItsValue) {
  EXPECT_EQ(format_error_of(R"({"running":"yes","pid":50})"),
            R"(agnocastd status file: "running" must be true or false, not "yes")");
  EXPECT_EQ(format_error_of(R"({"running":true,"pid":-3})"),
            R"(agnocastd status file: "pid" must be an integer from 1 to 2147483647, not -3)");
  EXPECT_EQ(format_error_of(R"({"running":true,"pid":4294967296})"),
            "agnocastd status file: \"pid\" must be an integer from 1 to 2147483647, not "
            "4294967296");
  std::string fraction = to_json(running_daemon());
  fraction.replace(fraction.find("\"uptime_s\":7"), 12, "\"uptime_s\":7.5");
  EXPECT_EQ(format_error_of(fraction),
            "agnocastd status file: \"uptime_s\" must be an integer from 0 to "
            "18446744073709551615, not 7.5");
}

TEST(DaemonStatusJson, ModuleVersionMustAgreeWithModuleLoaded) {
  std::string text = to_json(running_daemon());
  text.replace(text.find(R"("0.1.0")"), 7, "null");
  EXPECT_NE(format_error_of(text).find("\"module_version\" must be a string when"),
            std::string::npos);
}

TEST(DaemonStatusJson, TextThatIsNoJsonObjectIsRefused) {
  EXPECT_EQ(format_error_of("{not json"), "agnocastd status file: not JSON");
  EXPECT_EQ(format_error_of(""), "agnocastd status file: not JSON");
  EXPECT_EQ(format_error_of("[1,2]"), "agnocastd status file: not a JSON object");
}

TEST(DaemonStatusPaths, TheLockIsBesideTheStatusFile) {
  EXPECT_EQ(daemon_lock_path_beside(daemon_status_path), daemon_lock_path);
  EXPECT_EQ(daemon_lock_path_beside("/tmp/x/agnocastd.json"), "/tmp/x/agnocastd.lock");
  EXPECT_EQ(daemon_lock_path_beside(std::string(runtime_directory) + "/agnocastd.json"),
            daemon_lock_path);
}

}  // namespace
}  // namespace agnocast
