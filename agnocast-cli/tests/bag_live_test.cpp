// agnocast-cli bag record against live publishers in the VM: every message
// published while it records is in the file, in order, byte-equal to what the
// generated serializer (and so agnocast-bridge) writes; SIGINT leaves a
// complete file, kill -9 one readable up to its last chunk; bad input is exit 2.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <agnocast_test/process.hpp>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sstream>
#include <std_msgs/msg/string.hpp>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/inspect.hpp"
#include "agnocast/mcap/reader.hpp"
#include "agnocast/mcap/writer.hpp"
#include "agnocast/schema_cdr.hpp"

namespace bag_live {

struct Text {
  agnocast::string data;
  std::uint64_t seq;
  agnocast::vector<std::int32_t> values;
  bool even;
};

}  // namespace bag_live

AGNOCAST_MESSAGE(bag_live::Text, "bag_live/msg/Text", data, seq, values, even);

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using nlohmann::json;

using agnocast_test::Outcome;
using agnocast_test::slurp;
using agnocast_test::wait_exit;

Outcome cli(const std::string& args) {
  return agnocast_test::run_shell("agnocast-cli " + args, "bag");
}

// agnocast-cli bag record ARGS... in the background.
pid_t start_recorder(const std::vector<std::string>& args) {
  std::vector<std::string> argv{"agnocast-cli", "bag", "record"};
  argv.insert(argv.end(), args.begin(), args.end());
  return agnocast_test::spawn(argv, "record.out", "record.err");
}

// Runs `node`'s callbacks until `player` exits and a moment after (what it
// published last is delivered); returns the player's exit status.
int spin_until_exit(agnocast::Node& node, pid_t player) {
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  const int code = wait_exit(player);
  std::this_thread::sleep_for(300ms);
  executor.cancel();
  spinner.join();
  return code;
}

template <class T>
bool wait_for_recorder(agnocast::Publisher<T>& publisher) {
  return publisher.wait_for_subscribers(1, 20s);
}

std::string long_text(std::uint64_t seq) {
  return "message " + std::to_string(seq) + " with a text longer than a small string";
}

// bag_live::Text as XCDR1, written field by field with the CDR writer the
// generated types use.
std::vector<std::uint8_t> expected_text_cdr(const bag_live::Text& text) {
  std::vector<std::uint8_t> out(agnocast::cdr::encapsulation_header.begin(),
                                agnocast::cdr::encapsulation_header.end());
  agnocast::cdr::Writer writer(out);
  writer.write(std::string(text.data.begin(), text.data.end()));
  writer.write(text.seq);
  writer.write(std::vector<std::int32_t>(text.values.begin(), text.values.end()));
  writer.write(text.even);
  return out;
}

struct Recorded {
  std::string topic;
  std::vector<std::uint8_t> bytes;
  std::uint64_t log_time;
  std::uint64_t publish_time;
};

std::vector<Recorded> read_all(const std::string& path, agnocast::mcap::ScanResult& result) {
  const agnocast::mcap::Reader reader(path);
  std::map<std::uint16_t, std::string> topics;
  std::vector<Recorded> read;
  agnocast::mcap::Visitor visitor;
  visitor.channel = [&](const agnocast::mcap::Channel& channel) {
    topics[channel.id] = channel.topic;
  };
  visitor.message = [&](const agnocast::mcap::MessageView& message) {
    read.push_back({topics.at(message.channel_id),
                    {message.data.begin(), message.data.end()},
                    message.log_time,
                    message.publish_time});
  };
  result = reader.scan(visitor);
  return read;
}

class BagLive : public ::testing::Test {
 protected:
  agnocast::Node node_{"bag_live_publisher"};
};

TEST_F(BagLive, RecordsEveryMessageByteEqualAndInOrder) {
  auto text = node_.create_publisher<bag_live::Text>("/bag_text", agnocast::QoS(10));
  auto cloud =
      node_.create_publisher<sensor_msgs::msg::PointCloud2>("/bag_cloud", agnocast::QoS(10));
  const pid_t recorder = start_recorder({"-o", "run.mcap", "/bag_text", "/bag_cloud"});
  ASSERT_TRUE(wait_for_recorder(*text)) << slurp("record.err");
  ASSERT_TRUE(wait_for_recorder(*cloud)) << slurp("record.err");

  std::vector<std::vector<std::uint8_t>> texts;
  std::vector<std::vector<std::uint8_t>> clouds;
  const auto wall_start = std::chrono::system_clock::now();
  for (std::uint64_t seq = 1; seq <= 40; ++seq) {
    auto message = text->borrow_loaned_message();
    message->data = long_text(seq);
    message->seq = seq;
    for (std::uint64_t i = 0; i < seq % 5; ++i) {
      message->values.push_back(static_cast<std::int32_t>(seq * 100 + i));
    }
    message->even = seq % 2 == 0;
    texts.push_back(expected_text_cdr(*message));
    text->publish(std::move(message));
    if (seq % 4 == 0) {
      auto points = cloud->borrow_loaned_message();
      points->header.frame_id = "lidar";
      points->height = 1;
      points->width = 4096;
      points->point_step = 16;
      points->row_step = 16 * 4096;
      points->data.resize(points->row_step);
      for (std::size_t b = 0; b < points->data.size(); ++b) {
        points->data[b] = static_cast<std::uint8_t>(b * 31 + seq);
      }
      clouds.push_back(agnocast::cdr::serialize(*points));
      cloud->publish(std::move(points));
    }
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(500ms);
  ::kill(recorder, SIGINT);
  ASSERT_EQ(wait_exit(recorder), 0) << slurp("record.err");
  const std::string summary = slurp("record.out");
  EXPECT_NE(summary.find("run.mcap"), std::string::npos) << summary;

  agnocast::mcap::ScanResult result;
  const std::vector<Recorded> read = read_all("run.mcap", result);
  EXPECT_TRUE(result.reached_data_end) << result.stopped;
  std::vector<std::vector<std::uint8_t>> read_texts;
  std::vector<std::vector<std::uint8_t>> read_clouds;
  const auto start_ns = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(wall_start.time_since_epoch()).count());
  for (const Recorded& message : read) {
    (message.topic == "/bag_text" ? read_texts : read_clouds).push_back(message.bytes);
    EXPECT_GE(message.log_time, start_ns);
    EXPECT_LE(message.publish_time, message.log_time);
    EXPECT_GE(message.publish_time + 1'000'000'000, message.log_time);
  }
  ASSERT_EQ(read_texts.size(), texts.size());
  ASSERT_EQ(read_clouds.size(), clouds.size());
  for (std::size_t i = 0; i < texts.size(); ++i) EXPECT_EQ(read_texts[i], texts[i]) << i;
  for (std::size_t i = 0; i < clouds.size(); ++i) EXPECT_EQ(read_clouds[i], clouds[i]) << i;

  const Outcome info = cli("bag info run.mcap --json");
  ASSERT_EQ(info.code, 0) << info.err;
  const json value = json::parse(info.out);
  EXPECT_EQ(value["complete"], true);
  EXPECT_EQ(value["compression"], "zstd");
  EXPECT_EQ(value["messages"], texts.size() + clouds.size());
  ASSERT_EQ(value["topics"].size(), 2u);
  EXPECT_EQ(value["topics"][0]["name"], "/bag_text");
  EXPECT_EQ(value["topics"][0]["type"], "bag_live/msg/Text");
  EXPECT_EQ(value["topics"][1]["type"], "sensor_msgs/msg/PointCloud2");
  // The recorder let go of every message: the kernel holds none for it.
  const auto topic = agnocast::topic_info("/bag_text");
  ASSERT_TRUE(topic);
  for (const auto& subscriber : topic->subscribers) EXPECT_EQ(subscriber.held, 0u);
}

TEST_F(BagLive, KilledRecorderLeavesAFileReadableUpToItsLastChunk) {
  auto cloud =
      node_.create_publisher<sensor_msgs::msg::PointCloud2>("/bag_kill", agnocast::QoS(10));
  const pid_t recorder = start_recorder({"-o", "killed.mcap", "--compression", "lz4", "/bag_kill"});
  ASSERT_TRUE(wait_for_recorder(*cloud)) << slurp("record.err");
  std::vector<std::vector<std::uint8_t>> published;
  for (std::uint64_t seq = 1; seq <= 30; ++seq) {
    auto points = cloud->borrow_loaned_message();
    points->header.frame_id = "lidar";
    points->data.resize(256 * 1024);
    for (std::size_t b = 0; b < points->data.size(); b += 97) {
      points->data[b] = static_cast<std::uint8_t>(seq + b);
    }
    published.push_back(agnocast::cdr::serialize(*points));
    cloud->publish(std::move(points));
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(500ms);
  ::kill(recorder, SIGKILL);
  wait_exit(recorder);

  const Outcome info = cli("bag info killed.mcap --json");
  ASSERT_EQ(info.code, 0) << info.err;
  const json value = json::parse(info.out);
  EXPECT_EQ(value["complete"], false);
  const auto messages = value["messages"].get<std::size_t>();
  // Chunks of ~1 MiB hold 4 messages each: all but the last few are there.
  EXPECT_GE(messages, 20u);
  EXPECT_LE(messages, published.size());
  EXPECT_NE(cli("bag info killed.mcap").out.find("Incomplete"), std::string::npos);

  agnocast::mcap::ScanResult result;
  const std::vector<Recorded> read = read_all("killed.mcap", result);
  EXPECT_FALSE(result.reached_data_end);
  ASSERT_EQ(read.size(), messages);
  for (std::size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i].bytes, published[i]) << i;

  // Cut anywhere, the file still reads up to a chunk: never a crash, never exit 2.
  const auto size = fs::file_size("killed.mcap");
  std::mt19937_64 random(25);
  for (int i = 0; i < 8; ++i) {
    fs::copy_file("killed.mcap", "cut.mcap", fs::copy_options::overwrite_existing);
    fs::resize_file("cut.mcap", 64 + random() % (size - 64));
    const Outcome cut = cli("bag info cut.mcap --json");
    ASSERT_EQ(cut.code, 0) << cut.err;
    EXPECT_EQ(json::parse(cut.out)["complete"], false);
    EXPECT_LE(json::parse(cut.out)["messages"].get<std::size_t>(), messages);
  }
}

TEST_F(BagLive, PlayedIntoFreshSubscribersByteEqualInOrderWithTheSpacing) {
  // Record a run first.
  std::vector<std::vector<std::uint8_t>> texts;
  std::vector<std::vector<std::uint8_t>> clouds;
  {
    agnocast::Node publisher_node("bag_play_source");
    auto text = publisher_node.create_publisher<bag_live::Text>("/play_text", agnocast::QoS(10));
    auto cloud = publisher_node.create_publisher<sensor_msgs::msg::PointCloud2>("/play_cloud",
                                                                                agnocast::QoS(10));
    const pid_t recorder = start_recorder({"-o", "play.mcap", "/play_text", "/play_cloud"});
    ASSERT_TRUE(wait_for_recorder(*text)) << slurp("record.err");
    ASSERT_TRUE(wait_for_recorder(*cloud)) << slurp("record.err");
    for (std::uint64_t seq = 1; seq <= 20; ++seq) {
      auto message = text->borrow_loaned_message();
      message->data = seq % 2 ? long_text(seq) : std::string("short");
      message->seq = seq;
      for (std::uint64_t i = 0; i < seq % 4; ++i) {
        message->values.push_back(static_cast<std::int32_t>(seq * 10 + i));
      }
      message->even = seq % 2 == 0;
      texts.push_back(expected_text_cdr(*message));
      text->publish(std::move(message));
      if (seq % 5 == 0) {
        auto points = cloud->borrow_loaned_message();
        points->header.frame_id = "a frame name longer than a small string";
        sensor_msgs::msg::PointField field;
        field.name = "x";
        field.datatype = 7;
        field.count = 1;
        points->fields.push_back(field);
        points->width = 1000;
        points->data.resize(16000);
        for (std::size_t b = 0; b < points->data.size(); ++b) {
          points->data[b] = static_cast<std::uint8_t>(b + seq);
        }
        clouds.push_back(agnocast::cdr::serialize(*points));
        cloud->publish(std::move(points));
      }
      std::this_thread::sleep_for(50ms);
    }
    std::this_thread::sleep_for(300ms);
    ::kill(recorder, SIGINT);
    ASSERT_EQ(wait_exit(recorder), 0) << slurp("record.err");
  }
  // The publishers are gone; fresh compiled subscribers take the played messages.
  agnocast::Node node("bag_play_sink");
  std::mutex lock;
  std::vector<std::vector<std::uint8_t>> got_texts;
  std::vector<std::vector<std::uint8_t>> got_clouds;
  std::vector<std::chrono::steady_clock::time_point> text_times;
  auto text_sub = node.create_subscription<bag_live::Text>(
      "/play_text", agnocast::QoS(100), [&](const bag_live::Text& message) {
        const std::lock_guard<std::mutex> guard(lock);
        got_texts.push_back(expected_text_cdr(message));
        text_times.push_back(std::chrono::steady_clock::now());
      });
  auto cloud_sub = node.create_subscription<sensor_msgs::msg::PointCloud2>(
      "/play_cloud", agnocast::QoS(100), [&](const sensor_msgs::msg::PointCloud2& message) {
        const std::lock_guard<std::mutex> guard(lock);
        got_clouds.push_back(agnocast::cdr::serialize(message));
      });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  std::thread spinner([&] { executor.spin(); });
  const Outcome played = cli("bag play play.mcap");
  std::this_thread::sleep_for(500ms);
  executor.cancel();
  spinner.join();
  ASSERT_EQ(played.code, 0) << played.err << played.out;
  const std::lock_guard<std::mutex> guard(lock);
  ASSERT_EQ(got_texts.size(), texts.size()) << played.out;
  ASSERT_EQ(got_clouds.size(), clouds.size()) << played.out;
  for (std::size_t i = 0; i < texts.size(); ++i) EXPECT_EQ(got_texts[i], texts[i]) << i;
  for (std::size_t i = 0; i < clouds.size(); ++i) EXPECT_EQ(got_clouds[i], clouds[i]) << i;
  // 20 messages 50 ms apart: played over about 0.95 s, not at once.
  const double span = std::chrono::duration<double>(text_times.back() - text_times.front()).count();
  EXPECT_GT(span, 0.7);
  EXPECT_LT(span, 2.0);

  // A topic already in use with another type is refused, naming it.
  // (/bag_text held bag_live/msg/Text in run.mcap; its endpoints are gone.)
  auto other = node.create_publisher<sensor_msgs::msg::PointCloud2>("/bag_text", agnocast::QoS(1));
  const Outcome wrong = cli("bag play run.mcap --topics /bag_text --rate 100");
  EXPECT_EQ(wrong.code, 2) << wrong.err;
  EXPECT_NE(wrong.err.find("/bag_text"), std::string::npos) << wrong.err;
  EXPECT_NE(wrong.err.find("sensor_msgs/msg/PointCloud2"), std::string::npos) << wrong.err;
}

// std_msgs/msg/String as XCDR1: the header, the length with its NUL, the bytes.
std::vector<std::uint8_t> string_cdr(const std::string& text) {
  const auto length = static_cast<std::uint32_t>(text.size() + 1);
  std::vector<std::uint8_t> out(4 + 4 + length, 0);
  out[1] = 1;
  std::memcpy(out.data() + 4, &length, sizeof length);
  std::memcpy(out.data() + 8, text.data(), text.size());
  return out;
}

// A file another tool wrote (no agnocast metadata), of a standard type, plays
// with no subscriber running first: the type's layout is compiled into the
// CLI. A compiled subscriber that joins later is accepted (same type hash)
// and decodes what comes.
TEST_F(BagLive, AForeignFileOfAStandardTypePlaysWithoutASubscriberFirst) {
  {
    agnocast::mcap::Writer writer("foreign.mcap",
                                  {.profile = "ros2",
                                   .library = "another tool",
                                   .compression = agnocast::mcap::Compression::Zstd});
    const std::string text = "string data\n";
    const auto schema =
        writer.add_schema("std_msgs/msg/String", "ros2msg", {text.begin(), text.end()});
    const auto channel = writer.add_channel(schema, "/foreign_text", "cdr", {});
    const std::uint64_t t0 = 1'700'000'000'000'000'000;
    for (std::uint64_t i = 0; i < 40; ++i) {
      writer.write_message(channel, t0 + i * 100'000'000, t0,
                           string_cdr("message " + std::to_string(i)));
    }
    writer.close();
  }
  ASSERT_FALSE(agnocast::topic_info("/foreign_text"));
  const pid_t player = ::fork();
  if (player == 0) {
    const int out = ::open("play.out", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open("play.err", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execlp("agnocast-cli", "agnocast-cli", "bag", "play", "foreign.mcap",
             static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // The player's publisher appears, with the standard type.
  std::optional<agnocast::TopicInfo> info;
  for (int i = 0; i < 200 && !(info = agnocast::topic_info("/foreign_text")); ++i) {
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(info) << slurp("play.err");
  EXPECT_EQ(info->type_name, "std_msgs/msg/String");
  agnocast::Node node("foreign_sink");
  std::mutex lock;
  std::vector<std::string> got;
  auto subscription = node.create_subscription<std_msgs::msg::String>(
      "/foreign_text", agnocast::QoS(100), [&](const std_msgs::msg::String& message) {
        const std::lock_guard<std::mutex> guard(lock);
        got.emplace_back(message.data.begin(), message.data.end());
      });
  const int code = spin_until_exit(node, player);
  ASSERT_EQ(code, 0) << slurp("play.err") << slurp("play.out");
  const std::lock_guard<std::mutex> guard(lock);
  // 40 messages over 3.9 s; the subscriber joined within the first second.
  ASSERT_GE(got.size(), 25u) << slurp("play.out");
  const std::string last = "message 39";
  EXPECT_EQ(got.back(), last);
  for (std::size_t i = 1; i < got.size(); ++i) {
    EXPECT_EQ(std::stoi(got[i].substr(8)), std::stoi(got[i - 1].substr(8)) + 1) << got[i];
  }
}

// A file another tool wrote of a type the CLI was not built with, and that
// no running program has registered: bag play lays the type out from the
// definition in the file (constants and comments included, as rosbag2 writes
// it), so a subscriber compiled from the same fields that starts after the
// player is accepted (same type hash) and receives every field exact.
TEST_F(BagLive, AForeignFileOfAUserTypePlaysFromItsDefinitionWithoutASubscriberFirst) {
  const std::string definition =
      "# Text as another tool records it\n"
      "uint8 KIND_PLAIN=0\n"
      "string data\n"
      "uint64 seq  # counts from 0\n"
      "int32[] values\n"
      "bool even\n";
  const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<bag_live::Text>());
  {
    agnocast::mcap::Writer writer("foreign_user.mcap",
                                  {.profile = "ros2",
                                   .library = "another tool",
                                   .compression = agnocast::mcap::Compression::Lz4});
    const auto schema_id =
        writer.add_schema("bag_live/msg/Text", "ros2msg", {definition.begin(), definition.end()});
    const auto channel = writer.add_channel(schema_id, "/foreign_user", "cdr", {});
    const std::uint64_t t0 = 1'700'000'000'000'000'000;
    for (std::uint64_t i = 0; i < 60; ++i) {
      bag_live::Text text;
      text.data = ("text " + std::to_string(i)).c_str();
      text.seq = i;
      for (std::int32_t v = 0; v < static_cast<std::int32_t>(i % 5); ++v) {
        text.values.push_back(v * 1000 - static_cast<std::int32_t>(i));
      }
      text.even = i % 2 == 0;
      std::vector<std::uint8_t> cdr;
      agnocast::serialize_with_schema(&text, schema, cdr);
      writer.write_message(channel, t0 + i * 50'000'000, t0, cdr);
    }
    writer.close();
  }
  ASSERT_FALSE(agnocast::topic_info("/foreign_user"));
  const pid_t player = agnocast_test::spawn({"agnocast-cli", "bag", "play", "foreign_user.mcap"},
                                            "play_user.out", "play_user.err");
  std::optional<agnocast::TopicInfo> info;
  for (int i = 0; i < 200 && !(info = agnocast::topic_info("/foreign_user")); ++i) {
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(info) << slurp("play_user.err");
  EXPECT_EQ(info->type_name, "bag_live/msg/Text");
  EXPECT_EQ(info->type_hash, agnocast::message_traits<bag_live::Text>::type_hash);
  agnocast::Node node("foreign_user_sink");
  std::mutex lock;
  std::vector<std::uint64_t> seqs;
  std::vector<std::string> problems;
  auto subscription = node.create_subscription<bag_live::Text>(
      "/foreign_user", agnocast::QoS(100), [&](const bag_live::Text& text) {
        const std::lock_guard<std::mutex> guard(lock);
        const std::uint64_t i = text.seq;
        seqs.push_back(i);
        std::vector<std::int32_t> expected;
        for (std::int32_t v = 0; v < static_cast<std::int32_t>(i % 5); ++v) {
          expected.push_back(v * 1000 - static_cast<std::int32_t>(i));
        }
        if (std::string(text.data.c_str()) != "text " + std::to_string(i) ||
            std::vector<std::int32_t>(text.values.begin(), text.values.end()) != expected ||
            text.even != (i % 2 == 0)) {
          problems.push_back("message " + std::to_string(i) + " differs");
        }
      });
  const int code = spin_until_exit(node, player);
  ASSERT_EQ(code, 0) << slurp("play_user.err") << slurp("play_user.out");
  const std::lock_guard<std::mutex> guard(lock);
  EXPECT_TRUE(problems.empty()) << problems.front();
  // 60 messages over 2.95 s; the subscriber joined within the first second.
  ASSERT_GE(seqs.size(), 30u) << slurp("play_user.out");
  EXPECT_EQ(seqs.back(), 59u);
  for (std::size_t i = 1; i < seqs.size(); ++i) EXPECT_EQ(seqs[i], seqs[i - 1] + 1);
}

// Hostile files: bag play names the file and exits 2 for one it cannot open,
// and plays what a damaged one holds, saying where it stops.
TEST_F(BagLive, HostileFilesAreNamedNeverACrash) {
  {
    agnocast::mcap::Writer writer("hostile.mcap", {.profile = "ros2", .chunk_size = 256});
    const std::string text = "string data\n";
    const auto schema =
        writer.add_schema("std_msgs/msg/String", "ros2msg", {text.begin(), text.end()});
    const auto channel = writer.add_channel(schema, "/hostile_text", "cdr", {});
    for (std::uint64_t i = 0; i < 40; ++i) {
      writer.write_message(channel, 1000 + i, 1000, string_cdr("message " + std::to_string(i)));
    }
    writer.close();
  }
  auto patch = [](const char* path, std::uint64_t offset, auto value) {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(static_cast<std::streamoff>(offset));
    file.write(reinterpret_cast<const char*>(&value), sizeof value);
  };
  fs::copy_file("hostile.mcap", "header.mcap", fs::copy_options::overwrite_existing);
  patch("header.mcap", 9, std::uint64_t{1} << 62);  // the Header's length
  Outcome r = cli("bag play header.mcap");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("header.mcap"), std::string::npos) << r.err;
  r = cli("bag info header.mcap");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("header.mcap"), std::string::npos) << r.err;

  // The third chunk declares 2^60 bytes: the two before it play.
  std::uint64_t third = 0;
  {
    const agnocast::mcap::Reader reader("hostile.mcap");
    ASSERT_TRUE(reader.summary());
    ASSERT_GE(reader.summary()->chunk_indexes.size(), 4u);
    third = reader.summary()->chunk_indexes[2].chunk_start_offset;
  }
  fs::copy_file("hostile.mcap", "chunk.mcap", fs::copy_options::overwrite_existing);
  patch("chunk.mcap", third + 9 + 16, std::uint64_t{1} << 60);
  r = cli("bag play chunk.mcap --rate 1000");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("chunk.mcap ends early"), std::string::npos) << r.out;
  r = cli("bag info chunk.mcap --json");
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(BagLive, BadInputIsExitTwoNamingIt) {
  Outcome r = cli("bag record -o none.mcap /bag_no_such_topic --duration 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/bag_no_such_topic"), std::string::npos) << r.err;
  std::ofstream("garbage.mcap") << "this is not an MCAP file";
  r = cli("bag info garbage.mcap");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("garbage.mcap"), std::string::npos) << r.err;
  r = cli("bag info missing.mcap --json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(json::parse(r.out)["exit_code"], 2);
  r = cli("bag record");
  EXPECT_EQ(r.code, 2);
}

TEST_F(BagLive, DurationStopsWithACompleteFile) {
  auto text = node_.create_publisher<bag_live::Text>("/bag_duration", agnocast::QoS(10));
  const Outcome r = cli("bag record -o dir/ /bag_duration --duration 1 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const json summary = json::parse(r.out);
  ASSERT_EQ(summary["files"].size(), 1u);
  const std::string file = summary["files"][0];
  EXPECT_EQ(fs::path(file).parent_path(), "dir");
  const Outcome info = cli("bag info " + file + " --json");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_EQ(json::parse(info.out)["complete"], true);
}

}  // namespace
