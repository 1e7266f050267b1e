// agnocast-bench-heap: a message written with std containers, published
// through the allocation hook, next to the same message with agnocast
// containers. Per message: the cost of filling a loan (borrow, then the
// members' allocations and writes) and the one-way latency to a subscriber in
// another process (publish call to its callback, both asleep before each
// sample). A third row fills the std message outside any loan, from glibc
// behind the hook: what the hook costs an ordinary allocation.
// Linked with agnocast::heaphook; needs the kernel module (run it in the VM).
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace bench {

struct Point {
  float x = 0, y = 0, z = 0;
};

struct StdCloud {
  std::uint64_t seq = 0;
  std::int64_t stamp_ns = 0;
  std::string frame_id;
  std::vector<std::uint8_t> payload;
  std::vector<Point> points;
};

struct AgnocastCloud {
  std::uint64_t seq = 0;
  std::int64_t stamp_ns = 0;
  agnocast::string frame_id;
  agnocast::vector<std::uint8_t> payload;
  agnocast::vector<Point> points;
};

}  // namespace bench

AGNOCAST_HEAP_MESSAGE(bench::StdCloud, "bench/msg/StdCloud", seq, stamp_ns, frame_id, payload,
                      points);
AGNOCAST_MESSAGE(bench::AgnocastCloud, "bench/msg/AgnocastCloud", seq, stamp_ns, frame_id, payload,
                 points);

namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Shape {
  std::size_t payload_bytes;
  std::size_t points;
};

// The same work on either message: one string, one resize, growth by push_back.
template <class Cloud>
void fill(Cloud& cloud, std::uint64_t seq, const Shape& shape) {
  cloud.seq = seq;
  cloud.frame_id = "lidar_front_left, beyond the short-string buffer";
  cloud.payload.resize(shape.payload_bytes, static_cast<std::uint8_t>(seq));
  for (std::size_t i = 0; i < shape.points; ++i) {
    cloud.points.push_back({static_cast<float>(i), 0, 1});
  }
}

double percentile(std::vector<std::int64_t> samples, double p) {
  if (samples.empty()) return 0;
  std::sort(samples.begin(), samples.end());
  const auto at = static_cast<std::size_t>(p * static_cast<double>(samples.size() - 1));
  return static_cast<double>(samples[at]) / 1000.0;
}

// The subscriber process: one subscription per type; writes each latency to out.
int subscribe(const std::string& topic, std::size_t samples, int out) {
  agnocast::Node node{"bench_heap_subscriber"};
  std::size_t received = 0;
  auto record = [&](char kind, std::int64_t stamp) {
    const std::int64_t latency = now_ns() - stamp;
    char line[64];
    const int length =
        std::snprintf(line, sizeof line, "%c %lld\n", kind, static_cast<long long>(latency));
    (void)!::write(out, line, static_cast<std::size_t>(length));
    ++received;
  };
  auto std_sub = node.create_subscription<bench::StdCloud>(
      topic + "/std", agnocast::QoS{10},
      [&](const bench::StdCloud& cloud) { record('s', cloud.stamp_ns); });
  auto agnocast_sub = node.create_subscription<bench::AgnocastCloud>(
      topic + "/agnocast", agnocast::QoS{10},
      [&](const bench::AgnocastCloud& cloud) { record('a', cloud.stamp_ns); });
  agnocast::SingleThreadedExecutor executor;
  executor.add_node(node);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (received < 2 * samples && std::chrono::steady_clock::now() < deadline) {
    executor.spin_once(std::chrono::milliseconds(100));
  }
  return received == 2 * samples ? 0 : 1;
}

template <class Cloud>
std::int64_t publish_one(agnocast::Publisher<Cloud>& publisher, std::uint64_t seq,
                         const Shape& shape) {
  const std::int64_t start = now_ns();
  auto cloud = publisher.borrow_loaned_message();
  fill(*cloud, seq, shape);
  const std::int64_t filled = now_ns();
  cloud->stamp_ns = now_ns();
  publisher.publish(std::move(cloud));
  return filled - start;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"std containers through the allocation hook next to agnocast containers"};
  std::size_t samples = 1000;
  Shape shape{64 * 1024, 1000};
  app.add_option("--samples", samples, "messages of each type");
  app.add_option("--payload", shape.payload_bytes, "payload bytes per message");
  app.add_option("--points", shape.points, "points per message, added one by one");
  CLI11_PARSE(app, argc, argv);

  if (!agnocast::heap_scope::hook_active()) {
    std::fprintf(stderr, "agnocast-bench-heap: the allocation hook is not active\n");
    return 1;
  }
  const std::string topic = "/bench_heap_" + std::to_string(::getpid());
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return 1;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(pipe_fds[0]);
    try {
      ::_exit(subscribe(topic, samples, pipe_fds[1]));
    } catch (const std::exception& error) {
      std::fprintf(stderr, "agnocast-bench-heap: subscriber: %s\n", error.what());
      ::_exit(1);
    }
  }
  ::close(pipe_fds[1]);

  std::vector<std::int64_t> fill_std, fill_agnocast, fill_private;
  try {
    agnocast::Node node{"bench_heap_publisher"};
    auto std_pub = node.create_publisher<bench::StdCloud>(topic + "/std", agnocast::QoS{10});
    auto agnocast_pub =
        node.create_publisher<bench::AgnocastCloud>(topic + "/agnocast", agnocast::QoS{10});
    if (!std_pub->wait_for_subscribers(1, std::chrono::seconds(30)) ||
        !agnocast_pub->wait_for_subscribers(1, std::chrono::seconds(30))) {
      std::fprintf(stderr, "agnocast-bench-heap: no subscriber\n");
      return 1;
    }
    for (std::size_t i = 0; i < samples; ++i) {
      fill_std.push_back(publish_one(*std_pub, i, shape));
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      fill_agnocast.push_back(publish_one(*agnocast_pub, i, shape));
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      const std::int64_t start = now_ns();
      {
        bench::StdCloud cloud;
        fill(cloud, i, shape);
        fill_private.push_back(now_ns() - start);
      }
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "agnocast-bench-heap: the subscriber did not receive everything\n");
      return 1;
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-bench-heap: %s\n", error.what());
    ::kill(child, SIGTERM);
    return 1;
  }
  std::vector<std::int64_t> latency_std, latency_agnocast;
  FILE* in = ::fdopen(pipe_fds[0], "r");
  char kind;
  long long latency;
  while (std::fscanf(in, " %c %lld", &kind, &latency) == 2) {
    (kind == 's' ? latency_std : latency_agnocast).push_back(latency);
  }
  std::fclose(in);

  std::printf("%zu messages of each type: %zu payload bytes, %zu points added one by one\n",
              samples, shape.payload_bytes, shape.points);
  std::printf("%-38s %12s %12s %12s %12s\n", "message", "fill p50 us", "fill p99 us", "latency p50",
              "latency p99");
  auto row = [](const char* name, const std::vector<std::int64_t>& fill,
                const std::vector<std::int64_t>* latencies) {
    std::printf("%-38s %12.1f %12.1f", name, percentile(fill, 0.5), percentile(fill, 0.99));
    if (latencies) {
      std::printf(" %9.1f us %9.1f us\n", percentile(*latencies, 0.5),
                  percentile(*latencies, 0.99));
    } else {
      std::printf(" %12s %12s\n", "-", "-");
    }
  };
  row("agnocast::vector (AGNOCAST_MESSAGE)", fill_agnocast, &latency_agnocast);
  row("std::vector through the hook", fill_std, &latency_std);
  row("std::vector, private (glibc via hook)", fill_private, nullptr);
  return 0;
}
