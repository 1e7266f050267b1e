// agnocast-talker: publishes integrity-checkable messages.
#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <thread>

#include "chatter_message.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Sleeps until deadline in short slices so that SIGINT/SIGTERM end it promptly.
void sleep_until(Clock::time_point deadline) {
  while (agnocast::ok() && Clock::now() < deadline) {
    std::this_thread::sleep_for(
        std::min<Clock::duration>(deadline - Clock::now(), std::chrono::milliseconds(50)));
  }
}

// Exiting drops our unreceived entries, so give subscribers a moment to take the last ones.
void wait_for_subscribers(const std::string& topic, double linger_s) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(linger_s);
  while (agnocast::ok() && Clock::now() < deadline) {
    const auto info = agnocast::topic_info(topic);
    bool drained = true;
    if (info) {
      for (const auto& subscriber : info->subscribers) {
        if (!subscriber.polling && subscriber.unreceived > 0) drained = false;
      }
    }
    if (drained) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Publishes messages whose payload is derived from their sequence number."};
  std::string topic;
  std::uint64_t count = 0;
  double rate = 10.0;
  std::size_t size = 64;
  std::size_t depth = 10;
  bool transient_local = false;
  std::string node_name = "talker";
  double linger = 2.0;
  app.add_option("--topic", topic, "topic to publish on")->required();
  app.add_option("--count", count, "messages to publish (0: until SIGINT/SIGTERM)");
  app.add_option("--rate", rate, "messages per second (0: as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--size", size, "payload bytes per message");
  app.add_option("--depth", depth, "QoS depth");
  app.add_flag("--transient-local", transient_local,
               "keep the last depth messages for late joiners");
  app.add_option("--node", node_name, "node name shown by agnocast-cli");
  app.add_option("--linger", linger, "after the last message, seconds to wait for subscribers")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  try {
    agnocast::install_signal_handlers();
    agnocast::Node node{node_name};
    agnocast::QoS qos{depth};
    if (transient_local) qos.transient_local();
    auto publisher = node.create_publisher<chatter::Message>(topic, qos);

    const auto period =
        rate > 0
            ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate))
            : Clock::duration::zero();
    auto next = Clock::now();
    std::uint64_t published = 0;
    while (agnocast::ok() && (count == 0 || published < count)) {
      auto message = publisher->borrow_loaned_message();
      chatter::fill(*message, published, size);
      publisher->publish(std::move(message));
      ++published;
      if (period != Clock::duration::zero()) {
        next += period;
        sleep_until(next);
      }
    }
    wait_for_subscribers(topic, linger);
    std::fprintf(stderr, "agnocast-talker: published %llu messages on %s\n",
                 static_cast<unsigned long long>(published), topic.c_str());
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-talker: %s\n", error.what());
    return 1;
  }
}
