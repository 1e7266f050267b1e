#include "agnocast/status.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>
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

// The fields of running_daemon()'s file, as key and JSON value.
const std::vector<std::pair<std::string, std::string>> running_daemon_fields = {
    {"running", "true"},        {"pid", "321"},
    {"module_loaded", "true"},  {"module_version", "\"0.1.0\""},
    {"uptime_s", "7"},          {"started_at", "1700000000"},
    {"processes_cleaned", "2"}, {"queues_removed", "3"},
    {"shm_removed", "1"}};

// running_daemon()'s file without `left_out`, and with `changed` given another value.
std::string status_text(const std::string& left_out, const std::string& changed = "",
                        const std::string& value = "") {
  std::string text;
  for (const auto& [key, original] : running_daemon_fields) {
    if (key == left_out) continue;
    text += (text.empty() ? "{\"" : ",\"") + key + "\":" + (key == changed ? value : original);
  }
  return text + "}";
}

TEST(DaemonStatusJson, TheFieldsAreThoseItWrites) {
  EXPECT_EQ(daemon_status_from_json(status_text("")), running_daemon());
}

TEST(DaemonStatusJson, AMissingFieldIsNamed) {
  for (const auto& [key, value] : running_daemon_fields) {
    EXPECT_EQ(format_error_of(status_text(key)),
              "agnocastd status file: \"" + key + "\" is missing");
  }
}

TEST(DaemonStatusJson, AFieldOfAnotherTypeIsNamedWithItsValue) {
  EXPECT_EQ(format_error_of(status_text("", "running", "\"yes\"")),
            R"(agnocastd status file: "running" must be true or false, not "yes")");
  EXPECT_EQ(format_error_of(status_text("", "pid", "-3")),
            R"(agnocastd status file: "pid" must be an integer from 1 to 2147483647, not -3)");
  EXPECT_EQ(format_error_of(status_text("", "pid", "4294967296")),
            "agnocastd status file: \"pid\" must be an integer from 1 to 2147483647, not "
            "4294967296");
  EXPECT_EQ(format_error_of(status_text("", "uptime_s", "7.5")),
            "agnocastd status file: \"uptime_s\" must be an integer from 0 to "
            "18446744073709551615, not 7.5");
}

TEST(DaemonStatusJson, ModuleVersionMustAgreeWithModuleLoaded) {
  EXPECT_NE(format_error_of(status_text("", "module_version", "null"))
                .find("\"module_version\" must be a string when"),
            std::string::npos);
  EXPECT_NE(format_error_of(status_text("", "module_loaded", "false"))
                .find("\"module_version\" must be a string when"),
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
