// agnocast-cli topic echo against live publishers in the VM: generated
// standard messages (geometry_msgs/msg/PoseStamped, std_msgs/msg/String, and
// visualization_msgs/msg/InteractiveMarkerUpdate, the standard type with the
// largest schema) and a nested custom type declared with AGNOCAST_MESSAGE. The CLI runs in its own
// process and decodes what this process publishes from the schema alone; every field it prints must
// equal what was published.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast_test/process.hpp>
#include <array>
#include <atomic>
#include <chrono>
#include <fstream>
#include <geometry_msgs/msg/pose_stamped.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <std_msgs/msg/string.hpp>
#include <string>
#include <thread>
#include <vector>
#include <visualization_msgs/msg/interactive_marker_update.hpp>

namespace echo_live {

struct Sample {
  std::uint32_t id;
  agnocast::string name;
};

struct Batch {
  std::uint64_t seq;
  Sample head;
  agnocast::vector<Sample> samples;
  std::array<std::int16_t, 3> triple;
  agnocast::vector<double> weights;
  bool even;
};

}  // namespace echo_live

AGNOCAST_MESSAGE(echo_live::Sample, "echo_live/msg/Sample", id, name);
AGNOCAST_MESSAGE(echo_live::Batch, "echo_live/msg/Batch", seq, head, samples, triple, weights,
                 even);

namespace {

using agnocast_test::slurp;
using nlohmann::json;

using agnocast_test::Outcome;

Outcome cli(const std::string& args) {
  return agnocast_test::run_shell("agnocast-cli " + args, "echo");
}

std::vector<json> json_lines(const std::string& text) {
  std::vector<json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  return lines;
}

// Publishes with `fill(message, seq)` every 20 ms, seq counting from 1, until destroyed.
template <class T>
class SteadyPublisher {
 public:
  template <class Fill>
  SteadyPublisher(agnocast::Node& node, const std::string& topic, Fill fill)
      : publisher_(node.create_publisher<T>(topic, agnocast::QoS(10))), thread_([this, fill] {
          for (std::uint64_t seq = 1; !stop_; ++seq) {
            auto message = publisher_->borrow_loaned_message();
            fill(*message, seq);
            publisher_->publish(std::move(message));
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          }
        }) {}
  ~SteadyPublisher() {
    stop_ = true;
    thread_.join();
  }

 private:
  std::shared_ptr<agnocast::Publisher<T>> publisher_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

void fill_pose(geometry_msgs::msg::PoseStamped& pose, std::uint64_t seq) {
  pose.header.stamp.sec = static_cast<std::int32_t>(seq);
  pose.header.stamp.nanosec = static_cast<std::uint32_t>(seq * 1000);
  pose.header.frame_id = "frame-" + std::to_string(seq);
  pose.pose.position.x = static_cast<double>(seq) + 0.5;
  pose.pose.position.y = -static_cast<double>(seq);
  pose.pose.position.z = 0.25;
  pose.pose.orientation.w = 1.0;
}

json expected_pose(std::uint64_t seq) {
  return {
      {"header",
       {{"stamp", {{"sec", seq}, {"nanosec", seq * 1000}}},
        {"frame_id", "frame-" + std::to_string(seq)}}},
      {"pose",
       {{"position",
         {{"x", static_cast<double>(seq) + 0.5}, {"y", -static_cast<double>(seq)}, {"z", 0.25}}},
        {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}}};
}

// A name longer than any small-string buffer, so it lives in the pool.
std::string long_name(std::uint64_t seq) {
  return "sample number " + std::to_string(seq) + " with a long name";
}

void fill_batch(echo_live::Batch& batch, std::uint64_t seq) {
  batch.seq = seq;
  batch.head.id = static_cast<std::uint32_t>(seq);
  batch.head.name = "head";
  for (std::uint32_t i = 0; i < seq % 3 + 1; ++i) {
    batch.samples.push_back({i, agnocast::string(long_name(i).c_str())});
  }
  batch.triple = {1, -2, static_cast<std::int16_t>(seq)};
  batch.weights = {0.5, static_cast<double>(seq) * 0.25};
  batch.even = seq % 2 == 0;
}

json expected_batch(std::uint64_t seq) {
  json samples = json::array();
  for (std::uint32_t i = 0; i < seq % 3 + 1; ++i) {
    samples.push_back({{"id", i}, {"name", long_name(i)}});
  }
  return {{"seq", seq},
          {"head", {{"id", seq}, {"name", "head"}}},
          {"samples", samples},
          {"triple", {1, -2, seq}},
          {"weights", {0.5, static_cast<double>(seq) * 0.25}},
          {"even", seq % 2 == 0}};
}

void fill_string(std_msgs::msg::String& text, std::uint64_t seq) {
  text.data = "hello world " + std::to_string(seq);
}

void fill_update(visualization_msgs::msg::InteractiveMarkerUpdate& update, std::uint64_t seq) {
  update.server_id = "server";
  update.seq_num = seq;
  update.type = visualization_msgs::msg::InteractiveMarkerUpdate::UPDATE;
  visualization_msgs::msg::InteractiveMarker marker;
  marker.name = "handle";
  marker.scale = 0.5F;
  visualization_msgs::msg::InteractiveMarkerControl control;
  control.name = "move_x";
  control.interaction_mode = visualization_msgs::msg::InteractiveMarkerControl::MOVE_AXIS;
  visualization_msgs::msg::Marker shape;
  shape.type = visualization_msgs::msg::Marker::MESH_RESOURCE;
  shape.mesh_file.filename = "arrow.stl";
  shape.mesh_file.data = {1, 2, 3};
  shape.lifetime.sec = static_cast<std::int32_t>(seq);
  control.markers.push_back(shape);
  marker.controls.push_back(control);
  update.markers.push_back(marker);
  update.erases.push_back("old");
}

class TopicEchoLive : public ::testing::Test {
 protected:
  agnocast::Node node_{"echo_live_publisher"};
};

TEST_F(TopicEchoLive, GeneratedStandardMessageAsJsonLines) {
  SteadyPublisher<geometry_msgs::msg::PoseStamped> publisher(node_, "/echo_pose", fill_pose);
  const Outcome r = cli("topic echo /echo_pose --count 3 --json --timeout 30");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<json> messages = json_lines(r.out);
  ASSERT_EQ(messages.size(), 3u) << r.out;
  std::uint64_t previous = 0;
  for (const json& message : messages) {
    const auto seq = message.at("header").at("stamp").at("sec").get<std::uint64_t>();
    EXPECT_GT(seq, previous);
    previous = seq;
    EXPECT_EQ(message, expected_pose(seq));
  }
}

TEST_F(TopicEchoLive, StdMsgsStringAsJsonAndText) {
  SteadyPublisher<std_msgs::msg::String> publisher(node_, "/echo_string", fill_string);
  const Outcome r = cli("topic echo /echo_string --count 2 --json --timeout 30");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<json> messages = json_lines(r.out);
  ASSERT_EQ(messages.size(), 2u) << r.out;
  for (const json& message : messages) {
    ASSERT_EQ(message.size(), 1u) << message;
    EXPECT_TRUE(message.at("data").get<std::string>().starts_with("hello world ")) << message;
  }
  const Outcome text = cli("topic echo /echo_string --count 1 --timeout 30");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_TRUE(text.out.starts_with("data: \"hello world ")) << text.out;
  EXPECT_TRUE(text.out.ends_with("\"\n---\n")) << text.out;
}

TEST_F(TopicEchoLive, DeepestStandardTypeAsJsonLines) {
  SteadyPublisher<visualization_msgs::msg::InteractiveMarkerUpdate> publisher(node_, "/echo_update",
                                                                              fill_update);
  const Outcome r = cli("topic echo /echo_update --count 2 --json --timeout 30");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<json> messages = json_lines(r.out);
  ASSERT_EQ(messages.size(), 2u) << r.out;
  for (const json& message : messages) {
    const auto seq = message.at("seq_num").get<std::uint64_t>();
    EXPECT_EQ(message.at("server_id"), "server");
    EXPECT_EQ(message.at("type"), 1);
    EXPECT_EQ(message.at("erases"), json::array({"old"}));
    const json& marker = message.at("markers").at(0);
    EXPECT_EQ(marker.at("name"), "handle");
    EXPECT_EQ(marker.at("scale"), 0.5);
    EXPECT_EQ(marker.at("pose").at("orientation").at("w"), 1.0);  // the .msg default
    const json& control = marker.at("controls").at(0);
    EXPECT_EQ(control.at("name"), "move_x");
    EXPECT_EQ(control.at("interaction_mode"), 3);
    const json& shape = control.at("markers").at(0);
    EXPECT_EQ(shape.at("type"), 10);
    EXPECT_EQ(shape.at("lifetime").at("sec"), seq);
    EXPECT_EQ(shape.at("mesh_file").at("filename"), "arrow.stl");
    EXPECT_EQ(shape.at("mesh_file").at("data"), json::array({1, 2, 3}));
    EXPECT_EQ(shape.at("texture").at("data"), json::array());
  }
}

TEST_F(TopicEchoLive, NestedCustomTypeAsJsonLines) {
  SteadyPublisher<echo_live::Batch> publisher(node_, "/echo_batch", fill_batch);
  const Outcome r = cli("topic echo /echo_batch --count 3 --json --timeout 30");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<json> messages = json_lines(r.out);
  ASSERT_EQ(messages.size(), 3u) << r.out;
  for (const json& message : messages) {
    EXPECT_EQ(message, expected_batch(message.at("seq").get<std::uint64_t>()));
  }
}

// The text form of expected_batch(seq).
std::string expected_batch_text(std::uint64_t seq) {
  const std::string n = std::to_string(seq);
  std::string text = "seq: " + n + "\nhead:\n  id: " + n + "\n  name: \"head\"\nsamples:\n";
  for (std::uint32_t i = 0; i < seq % 3 + 1; ++i) {
    text += "  - id: " + std::to_string(i) + "\n    name: \"" + long_name(i) + "\"\n";
  }
  std::ostringstream weight;
  weight << static_cast<double>(seq) * 0.25;
  return text + "triple: [1, -2, " + n + "]\nweights: [0.5, " + weight.str() +
         "]\neven: " + (seq % 2 == 0 ? "true" : "false") + "\n---\n";
}

TEST_F(TopicEchoLive, NestedCustomTypeAsText) {
  SteadyPublisher<echo_live::Batch> publisher(node_, "/echo_batch", fill_batch);
  const Outcome r = cli("topic echo /echo_batch --count 1 --timeout 30");
  ASSERT_EQ(r.code, 0) << r.err;
  std::uint64_t seq = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str(), "seq: %lu", &seq), 1) << r.out;
  EXPECT_EQ(r.out, expected_batch_text(seq));
}

TEST_F(TopicEchoLive, TimeoutWithoutMessagesExitsOne) {
  auto quiet = node_.create_publisher<echo_live::Batch>("/echo_quiet", agnocast::QoS(10));
  const Outcome r = cli("topic echo /echo_quiet --timeout 0.5");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("0 messages on topic '/echo_quiet'"), std::string::npos) << r.err;
}

TEST_F(TopicEchoLive, UnknownTopicExitsOne) {
  const Outcome r = cli("topic echo /echo_nobody --count 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no publisher or subscriber uses topic '/echo_nobody'"), std::string::npos)
      << r.err;
}

}  // namespace
