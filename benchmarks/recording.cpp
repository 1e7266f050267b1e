#include "recording.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <agnocast/agnocast.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "agnocast/mcap/reader.hpp"
#include "bench_support.hpp"

namespace agnocast::bench {
namespace {

struct SmallMessage {
  std::uint64_t seq = 0;
  agnocast::vector<std::uint8_t> payload;
};

}  // namespace
}  // namespace agnocast::bench

AGNOCAST_MESSAGE(agnocast::bench::SmallMessage, "agnocast_bench/msg/Small", seq, payload);

namespace agnocast::bench {
namespace {

std::int64_t cpu_ns_of(const rusage& usage) {
  auto ns = [](const timeval& time) {
    return static_cast<std::int64_t>(time.tv_sec) * 1'000'000'000 +
           static_cast<std::int64_t>(time.tv_usec) * 1000;
  };
  return ns(usage.ru_utime) + ns(usage.ru_stime);
}

// x, y, z, intensity float32 points on a spiral (neither random nor
// constant bytes), `bytes` of them, computed once: under emulation the
// trigonometry would cost the publisher more than the recorder's work.
const std::vector<float>& spiral_points(std::size_t bytes) {
  static const std::vector<float> points = [bytes] {
    std::vector<float> out(bytes / sizeof(float));
    for (std::size_t p = 0; p < out.size() / 4; ++p) {
      const float angle = static_cast<float>(p) * 0.01F;
      const float radius = 2.0F + static_cast<float>(p % 1024) * 0.01F;
      out[4 * p + 0] = radius * std::cos(angle);
      out[4 * p + 1] = radius * std::sin(angle);
      out[4 * p + 2] = static_cast<float>(p / 1024) * 0.05F;
      out[4 * p + 3] = static_cast<float>(p % 256);
    }
    return out;
  }();
  return points;
}

// A PointCloud2 of `bytes` bytes of the spiral's points.
void fill_cloud(sensor_msgs::msg::PointCloud2& cloud, std::size_t bytes, std::uint64_t seq) {
  constexpr std::uint32_t point_step = 16;
  cloud.header.frame_id = "lidar";
  cloud.header.stamp.sec = static_cast<std::int32_t>(seq);
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(bytes / point_step);
  cloud.is_bigendian = false;
  cloud.point_step = point_step;
  cloud.row_step = cloud.width * point_step;
  cloud.is_dense = true;
  const char* names[] = {"x", "y", "z", "intensity"};
  cloud.fields.resize(4);
  for (std::uint32_t i = 0; i < 4; ++i) {
    cloud.fields[i].name = names[i];
    cloud.fields[i].offset = i * 4;
    cloud.fields[i].datatype = sensor_msgs::msg::PointField::FLOAT32;
    cloud.fields[i].count = 1;
  }
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step));
  const std::vector<float>& points = spiral_points(bytes);
  std::memcpy(cloud.data.data(), points.data(), cloud.data.size());
  std::memcpy(cloud.data.data(), &seq, sizeof seq);  // each message differs
}

// A child's user + system CPU time so far, from /proc (clock ticks).
std::int64_t process_cpu_ns(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const std::size_t name_end = line.rfind(')');
  if (name_end == std::string::npos) return 0;
  std::istringstream fields(line.substr(name_end + 2));
  std::string field;
  // After the name: the state is field 3; utime and stime are fields 14 and 15.
  for (int i = 3; i < 14 && fields >> field; ++i) {
  }
  long long utime = 0, stime = 0;
  fields >> utime >> stime;
  const long ticks = ::sysconf(_SC_CLK_TCK);
  return (utime + stime) * (1'000'000'000LL / (ticks > 0 ? ticks : 100));
}

template <typename Body>
pid_t spawn_role(Body body) {
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    int status = 1;
    try {
      status = body();
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench recording publisher: " << error.what() << "\n";
    }
    ::_exit(status);
  }
  return child;
}

// Publishes `count` messages at `period_ns` once the recorder subscribed.
// Tells the driver over `report` when it is ready and when it is done, then
// waits for a byte on `stop` before it goes (its pool stays until the
// recorder is finished).
template <typename Publish>
int publisher_role(const std::string& topic, std::size_t count, std::int64_t period_ns, int report,
                   int stop, Publish publish_one) {
  agnocast::Node node{"bench_recorded_publisher"};
  auto publisher = publish_one(node, topic, std::uint64_t{0}, /*create_only=*/true);
  char byte = 'r';
  write_all(report, &byte, 1);
  if (!publisher->wait_for_subscribers(1, std::chrono::seconds(60))) return 1;
  byte = 's';
  write_all(report, &byte, 1);
  std::int64_t next = now_ns();
  for (std::size_t seq = 0; seq < count; ++seq) {
    publish_one(node, topic, seq, false);
    next += period_ns;
    sleep_until_ns(next);
  }
  byte = 'd';
  write_all(report, &byte, 1);
  char stop_byte = 0;
  read_all(stop, &stop_byte, 1);
  return 0;
}

struct RecordingRun {
  std::size_t published = 0;
  std::uint64_t recorded = 0;
  std::uint64_t dropped_reported = 0;
  std::int64_t recorder_cpu_ns = 0;
  std::int64_t recorder_start_cpu_ns = 0;  // before the first message: start-up
  std::uintmax_t file_bytes = 0;
  double seconds = 0;
  bool complete = false;
};

// Runs agnocast-cli bag record on `topic` while `publisher` (already
// forked, reporting on `report`, stopped by a byte on `stop`) publishes.
RecordingRun record_while(const std::string& cli, const std::string& topic, std::size_t count,
                          pid_t publisher, Pipe& report, Pipe& stop) {
  char byte = 0;
  if (!read_all(report.read_fd, &byte, 1)) throw std::runtime_error("recorded publisher died");
  const std::string file = "/tmp/agnocast-bench-recording.mcap";
  const std::string summary = "/tmp/agnocast-bench-recording.json";
  std::error_code ignored;
  std::filesystem::remove(file, ignored);
  const std::int64_t started = now_ns();
  const pid_t recorder = ::fork();
  if (recorder < 0) throw std::runtime_error("fork failed");
  if (recorder == 0) {
    const int out = ::open(summary.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execl(cli.c_str(), "agnocast-cli", "bag", "record", "--json", "-o", file.c_str(),
            topic.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // The recorder subscribed: what it used so far is start-up.
  const bool started_publishing = read_all(report.read_fd, &byte, 1);
  const std::int64_t start_up_cpu_ns = started_publishing ? process_cpu_ns(recorder) : 0;
  const bool done = started_publishing && read_all(report.read_fd, &byte, 1);
  // What is still in flight reaches the file before the recorder stops.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ::kill(recorder, SIGINT);
  int status = 0;
  rusage usage{};
  while (::wait4(recorder, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  RecordingRun run;
  run.seconds = static_cast<double>(now_ns() - started) / 1e9;
  write_all(stop.write_fd, &byte, 1);
  int publisher_status = 0;
  while (::waitpid(publisher, &publisher_status, 0) < 0 && errno == EINTR) {
  }
  if (!done || !WIFEXITED(publisher_status) || WEXITSTATUS(publisher_status) != 0) {
    throw std::runtime_error("the recorded publisher failed");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("agnocast-cli bag record failed (status " + std::to_string(status) +
                             ")");
  }
  run.published = count;
  run.recorder_cpu_ns = cpu_ns_of(usage);
  run.recorder_start_cpu_ns = start_up_cpu_ns;
  run.file_bytes = std::filesystem::file_size(file);
  const agnocast::mcap::Reader reader(file);
  agnocast::mcap::Visitor visitor;
  const agnocast::mcap::ScanResult scanned = reader.scan(visitor);
  run.recorded = scanned.messages;
  run.complete = scanned.reached_data_end && scanned.stopped.empty();
  std::ifstream in(summary);
  nlohmann::json reported = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (reported.is_object() && reported.contains("topics")) {
    for (const nlohmann::json& entry : reported["topics"]) {
      run.dropped_reported += entry.value("dropped", std::uint64_t{0});
    }
  }
  std::filesystem::remove(file, ignored);
  std::filesystem::remove(summary, ignored);
  return run;
}

nlohmann::json run_json(const RecordingRun& run, std::size_t bytes, double rate_hz) {
  const double recorded = static_cast<double>(run.recorded);
  return {{"payload_bytes", bytes},
          {"rate_hz", rate_hz},
          {"published", run.published},
          {"recorded", run.recorded},
          {"lost", run.published > run.recorded ? run.published - run.recorded : 0},
          {"dropped_reported", run.dropped_reported},
          {"recorder_cpu_ms", static_cast<double>(run.recorder_cpu_ns) / 1e6},
          {"recorder_start_up_cpu_ms", static_cast<double>(run.recorder_start_cpu_ns) / 1e6},
          // From its subscription to its exit: the messages, the file's end.
          {"cpu_us_per_message",
           recorded > 0 ? nlohmann::json(
                              static_cast<double>(run.recorder_cpu_ns - run.recorder_start_cpu_ns) /
                              1e3 / recorded)
                        : nlohmann::json()},
          {"file_bytes", run.file_bytes},
          {"complete", run.complete},
          {"wall_s", run.seconds}};
}

}  // namespace

nlohmann::json run_recording(const std::string& cli, bool smoke) {
  int counter = 0;
  auto topic_name = [&](const char* kind) {
    return std::string("/bench/recorded_") + kind + "_" + std::to_string(::getpid()) + "_" +
           std::to_string(counter++);
  };
  nlohmann::json result = nlohmann::json::object();

  {
    constexpr std::size_t cloud_bytes = 4 << 20;
    constexpr double rate_hz = 20;
    const std::size_t count = smoke ? 2 : 40;
    const std::string topic = topic_name("cloud");
    Pipe report = Pipe::open(), stop = Pipe::open();
    using Cloud = sensor_msgs::msg::PointCloud2;
    std::shared_ptr<agnocast::Publisher<Cloud>> publisher;
    auto publish_one = [&](agnocast::Node& node, const std::string& name, std::uint64_t seq,
                           bool create_only) {
      if (create_only) {
        spiral_points(cloud_bytes);  // computed before the recorder starts
        publisher = node.create_publisher<Cloud>(name, agnocast::QoS{10});
        return publisher;
      }
      auto message = publisher->borrow_loaned_message();
      fill_cloud(*message, cloud_bytes, seq);
      publisher->publish(std::move(message));
      return publisher;
    };
    const pid_t child = spawn_role([&] {
      return publisher_role(topic, count, static_cast<std::int64_t>(1e9 / rate_hz), report.write_fd,
                            stop.read_fd, publish_one);
    });
    result["pointcloud2_4mib_20hz"] =
        run_json(record_while(cli, topic, count, child, report, stop), cloud_bytes, rate_hz);
  }
  {
    constexpr std::size_t small_bytes = 64;
    constexpr double rate_hz = 1000;
    const std::size_t count = smoke ? 50 : 5000;
    const std::string topic = topic_name("small");
    Pipe report = Pipe::open(), stop = Pipe::open();
    std::shared_ptr<agnocast::Publisher<SmallMessage>> publisher;
    auto publish_one = [&](agnocast::Node& node, const std::string& name, std::uint64_t seq,
                           bool create_only) {
      if (create_only) {
        publisher = node.create_publisher<SmallMessage>(name, agnocast::QoS{10});
        return publisher;
      }
      auto message = publisher->borrow_loaned_message();
      message->seq = seq;
      message->payload.resize(small_bytes);
      publisher->publish(std::move(message));
      return publisher;
    };
    const pid_t child = spawn_role([&] {
      return publisher_role(topic, count, static_cast<std::int64_t>(1e9 / rate_hz), report.write_fd,
                            stop.read_fd, publish_one);
    });
    result["small_64b_1khz"] =
        run_json(record_while(cli, topic, count, child, report, stop), small_bytes, rate_hz);
  }
  result["compression"] = "zstd";
  return result;
}

}  // namespace agnocast::bench
