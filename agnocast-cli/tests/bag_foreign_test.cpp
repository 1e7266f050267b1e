// A user type's .msg files travel from agnocast-msggen through the kernel's
// schema into what bag record writes and topic echo --definition prints, word
// for word (natively, @mcap/core and @foxglove/rosmsg read such a file:
// tests/mcap-readers).
//
// bag play of a file agnocast did not write: @mcap/core and
// @foxglove/rosmsg2-serialization write it in the VM (tests/mcap-readers/
// write-foreign.mjs), with a user type known only from the .msg text in the
// file and a channel recorded transient local. The player publishes it with
// no subscriber running; one that starts late gets every message, each field
// exactly as written.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <agnocast/agnocast.hpp>
#include <agnocast_test/process.hpp>
#include <chrono>
#include <fstream>
#include <golden_msgs/msg/wheel.hpp>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/inspect.hpp"
#include "agnocast/mcap/reader.hpp"

namespace {

using namespace std::chrono_literals;
using agnocast_test::slurp;

constexpr std::uint32_t message_count = 40;

// prefix, i and suffix: appended piece by piece (GCC 12 at -O3 warns falsely,
// -Wrestrict, on "literal" + std::string).
std::string numbered(const char* prefix, std::uint32_t i, const char* suffix = "") {
  std::string text = prefix;
  text += std::to_string(i);
  text += suffix;
  return text;
}

// What write-foreign.mjs's wheel(i) holds, field by field; empty when equal.
std::string differences(const golden_msgs::msg::Wheel& w, std::uint32_t i) {
  std::string out;
  auto check = [&](bool same, const char* field) {
    if (!same) out.append(field).append(" ");
  };
  const auto n = static_cast<std::int32_t>(i);
  check(w.header.stamp.sec == 1700000000 + n, "header.stamp.sec");
  check(w.header.stamp.nanosec == 1000 * i, "header.stamp.nanosec");
  check(w.header.frame_id.c_str() == numbered("wheel/", i), "header.frame_id");
  check(w.tire.pressure_kpa == 200 + i, "tire.pressure_kpa");
  check(w.tire.brand.c_str() == numbered("brand number ", i, " of the foreign file"), "tire.brand");
  check(w.name.c_str() == numbered("w", i), "name");
  check(w.radius == 0.25 * i, "radius");
  check(w.ticks == std::array<std::int32_t, 3>{n, -n, 2 * n}, "ticks");
  std::vector<float> speeds;
  for (std::uint32_t k = 0; k < i % 5; ++k) speeds.push_back(0.5F * static_cast<float>(k));
  check(std::vector<float>(w.speeds.begin(), w.speeds.end()) == speeds, "speeds");
  check(w.tags.size() == 1 && w.tags[0].c_str() == numbered("t", i), "tags");
  check(std::vector<std::uint8_t>(w.flags.begin(), w.flags.end()) ==
            std::vector<std::uint8_t>{1, static_cast<std::uint8_t>(i % 2 == 0)},
        "flags");
  check(w.enabled == (i % 3 == 0), "enabled");
  check(w.spares[0].pressure_kpa == i && w.spares[0].brand.empty(), "spares[0]");
  check(w.spares[1].pressure_kpa == 7 && std::string(w.spares[1].brand.c_str()) == "spare",
        "spares[1]");
  bool axes = w.axes.size() == i % 4;
  for (std::size_t k = 0; axes && k < w.axes.size(); ++k) {
    const auto x = static_cast<double>(k);
    axes = w.axes[k].x == x && w.axes[k].y == -x && w.axes[k].z == i;
  }
  check(axes, "axes");
  check(w.status == golden_msgs::msg::Wheel::MODE_DRIVE, "status");
  check(w.code == 65 + i % 26, "code");
  check(w.odometer == 9007199254740992ULL + i, "odometer");
  return out;
}

std::string msg_file(const std::string& name) {
  std::ifstream file("/opt/agnocast/bin/" + name + ".msg", std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(BagForeign, AUserTypeIsRecordedWithItsMsgFilesWordForWord) {
  const std::string wheel = msg_file("Wheel");
  const std::string tire = msg_file("Tire");
  ASSERT_FALSE(wheel.empty() || tire.empty());
  agnocast::Node node("recorded_wheel_source");
  auto publisher =
      node.create_publisher<golden_msgs::msg::Wheel>("/recorded_wheel", agnocast::QoS(10));

  const agnocast_test::Outcome echoed =
      agnocast_test::run_shell("agnocast-cli topic echo /recorded_wheel --definition", "echo");
  ASSERT_EQ(echoed.code, 0) << echoed.err;
  const std::string separator = std::string(80, '=') + "\n";
  EXPECT_EQ(echoed.out.rfind(wheel + separator, 0), 0u) << echoed.out;
  EXPECT_NE(echoed.out.find(separator + "MSG: golden_msgs/Tire\n" + tire), std::string::npos)
      << echoed.out;

  const pid_t recorder =
      agnocast_test::spawn({"agnocast-cli", "bag", "record", "-o", "wheel.mcap", "/recorded_wheel"},
                           "record.out", "record.err");
  ASSERT_TRUE(publisher->wait_for_subscribers(1, 20s)) << slurp("record.err");
  auto message = publisher->borrow_loaned_message();
  message->name = "recorded";
  publisher->publish(std::move(message));
  ::kill(recorder, SIGINT);
  int status = -1;
  ASSERT_TRUE(agnocast_test::eventually(
      [&] { return ::waitpid(recorder, &status, WNOHANG) == recorder; }, 20s));
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp("record.err");

  const agnocast::mcap::Reader reader("wheel.mcap");
  ASSERT_TRUE(reader.summary());
  ASSERT_EQ(reader.summary()->schemas.size(), 1u);
  const agnocast::mcap::Schema& schema = reader.summary()->schemas[0];
  EXPECT_EQ(schema.name, "golden_msgs/msg/Wheel");
  EXPECT_EQ(std::string(schema.data.begin(), schema.data.end()), echoed.out);
}

TEST(BagForeign, AFileWrittenByMcapCorePlaysIntoALateTransientLocalSubscriberExactly) {
  const std::string bin = "/opt/agnocast/bin/";
  ASSERT_EQ(std::system(("tar -xf " + bin + "mcap-readers.tar").c_str()), 0);
  const agnocast_test::Outcome written = agnocast_test::run_shell(
      "node write-foreign.mjs foreign.mcap " + std::to_string(message_count) +
          " golden_msgs/msg/Wheel=" + bin + "Wheel.msg std_msgs/Header=" + bin +
          "Header.msg builtin_interfaces/Time=" + bin + "Time.msg golden_msgs/Tire=" + bin +
          "Tire.msg geometry_msgs/Vector3=" + bin + "Vector3.msg",
      "write");
  ASSERT_EQ(written.code, 0) << written.err;

  ASSERT_FALSE(agnocast::topic_info("/foreign_wheel"));
  const pid_t player =
      agnocast_test::spawn({"agnocast-cli", "bag", "play", "foreign.mcap"}, "play.out", "play.err");
  // The player alone: the file's type, laid out from its text, is the
  // generated one; it offers transient local; a quarter of the file is out.
  std::optional<agnocast::TopicInfo> info;
  const bool started = agnocast_test::eventually(
      [&] {
        info = agnocast::topic_info("/foreign_wheel");
        return info && !info->publishers.empty() &&
               info->publishers[0].published >= message_count / 4;
      },
      20s);
  ASSERT_TRUE(started) << slurp("play.err");
  EXPECT_EQ(info->type_name, "golden_msgs/msg/Wheel");
  EXPECT_EQ(info->type_hash, agnocast::message_traits<golden_msgs::msg::Wheel>::type_hash);
  EXPECT_TRUE(info->publishers[0].transient_local);
  EXPECT_EQ(info->publishers[0].depth, 100u);
  EXPECT_TRUE(info->subscribers.empty());

  agnocast::Node node("foreign_wheel_sink");
  std::mutex lock;
  std::vector<std::uint32_t> seen;
  std::vector<std::string> problems;
  auto subscription = node.create_subscription<golden_msgs::msg::Wheel>(
      "/foreign_wheel", agnocast::QoS(100).transient_local(),
      [&](const golden_msgs::msg::Wheel& wheel) {
        const std::lock_guard<std::mutex> guard(lock);
        const auto i = static_cast<std::uint32_t>(wheel.tire.pressure_kpa - 200);
        seen.push_back(i);
        if (std::string wrong = differences(wheel, i); !wrong.empty()) {
          problems.push_back(numbered("message ", i, ": ") + wrong);
        }
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  const bool all = agnocast_test::eventually(
      [&] {
        const std::lock_guard<std::mutex> guard(lock);
        return seen.size() >= message_count;
      },
      20s);
  executor.cancel();
  spinner.join();
  int status = -1;
  const bool exited =
      agnocast_test::eventually([&] { return ::waitpid(player, &status, WNOHANG) == player; }, 20s);
  if (!exited) ::kill(player, SIGKILL);
  ASSERT_TRUE(exited) << "bag play did not end";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp("play.err");
  ASSERT_TRUE(all) << seen.size() << " of " << message_count << " messages";
  const std::lock_guard<std::mutex> guard(lock);
  EXPECT_TRUE(problems.empty()) << problems.front();
  std::vector<std::uint32_t> expected(message_count);
  for (std::uint32_t i = 0; i < message_count; ++i) expected[i] = i;
  EXPECT_EQ(seen, expected);
}

}  // namespace
