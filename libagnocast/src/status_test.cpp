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

TEST(StatusPaths, AServiceLockIsItsStatusFileWithTheLockExtension) {
  EXPECT_EQ(lock_path_beside(bridge_status_path), "/run/agnocast/bridge.lock");
  EXPECT_EQ(lock_path_beside(foxglove_status_path), "/run/agnocast/foxglove.lock");
  EXPECT_EQ(lock_path_beside(daemon_status_path), daemon_lock_path);
  EXPECT_EQ(lock_path_beside("/tmp/x/status"), "/tmp/x/status.lock");
}

ServiceStatus bridge_head() {
  return {"agnocast-bridge", 42, "0.1.0", ServiceState::running, 1700000000, 12, 1700000012};
}

std::string head_error_of(const std::string& text) {
  try {
    service_status_from_json(text);
  } catch (const StatusFormatError& error) {
    return error.what();
  }
  return "";
}

TEST(ServiceStatusJson, TheHeadsFieldsInTheirOrder) {
  EXPECT_EQ(to_json(bridge_head()),
            R"({"program":"agnocast-bridge","pid":42,"version":"0.1.0","state":"running",)"
            R"("running":true,"started_at":1700000000,"uptime_s":12,"written_at":1700000012})"
            "\n");
  ServiceStatus stopped = bridge_head();
  stopped.state = ServiceState::stopped;
  EXPECT_NE(to_json(stopped).find(R"("state":"stopped","running":false)"), std::string::npos);
}

TEST(ServiceStatusJson, ReadsBackWhatWasWrittenWhateverFollows) {
  for (const ServiceState state :
       {ServiceState::running, ServiceState::stopping, ServiceState::stopped}) {
    ServiceStatus head = bridge_head();
    head.state = state;
    EXPECT_EQ(service_status_from_json(to_json(head)), head);
  }
  std::string with_body = to_json(bridge_head());
  with_body.replace(with_body.rfind('}'), 1, R"(,"domain_id":0,"topics":[]})");
  EXPECT_EQ(service_status_from_json(with_body), bridge_head());
}

TEST(ServiceStatusJson, AgnocastdsFileHasTheHeadToo) {
  // agnocastd's fields restate the head's running, pid, uptime_s and started_at.
  std::string file = to_json(bridge_head());
  file.replace(file.rfind('}'), 1,
               R"(,"module_loaded":true,"module_version":"0.1.0","processes_cleaned":2,)"
               R"("queues_removed":3,"shm_removed":1})");
  const DaemonStatus daemon = daemon_status_from_json(file);
  EXPECT_TRUE(daemon.running);
  EXPECT_EQ(daemon.pid, 42);
  EXPECT_EQ(daemon.uptime_s, 12u);
  EXPECT_EQ(service_status_from_json(file).program, "agnocast-bridge");
}

TEST(ServiceStatusJson, ABadHeadIsNamed) {
  std::string text = to_json(bridge_head());
  EXPECT_EQ(head_error_of(R"({"pid":42})"), R"(status file: "program" is missing)");
  std::string bad_state = text;
  bad_state.replace(bad_state.find("\"running\","), 10, "\"asleep\",");
  EXPECT_EQ(head_error_of(bad_state),
            R"(status file: "state" must be "running", "stopping" or "stopped", not "asleep")");
  std::string disagreeing = text;
  disagreeing.replace(disagreeing.find("true"), 4, "false");
  EXPECT_NE(head_error_of(disagreeing).find(R"("running" must be false when)"), std::string::npos);
  EXPECT_EQ(head_error_of("[]"), "status file: not a JSON object");
}

}  // namespace
}  // namespace agnocast
