// agnocast-listener: verifies every message it receives.
#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <nlohmann/json.hpp>
#include <optional>

#include "chatter_message.hpp"

namespace {

struct Summary {
  std::uint64_t received = 0;
  std::uint64_t verified = 0;
  std::uint64_t corrupt = 0;
  std::optional<std::uint64_t> first_seq;
  std::optional<std::uint64_t> last_seq;
  std::uint64_t missed = 0;  // sequence numbers skipped between received messages
  std::uint64_t max_size = 0;

  void record(const chatter::Message& message) {
    ++received;
    if (!chatter::verify(message)) {
      ++corrupt;
      return;
    }
    ++verified;
    if (!first_seq) first_seq = message.seq;
    if (last_seq && message.seq > *last_seq + 1) missed += message.seq - *last_seq - 1;
    if (!last_seq || message.seq > *last_seq) last_seq = message.seq;
    max_size = std::max<std::uint64_t>(max_size, message.payload.size());
  }

  void print(bool json) const {
    if (json) {
      nlohmann::ordered_json out;
      out["received"] = received;
      out["corrupt"] = corrupt;
      out["first_seq"] = first_seq ? nlohmann::ordered_json(*first_seq) : nullptr;
      out["last_seq"] = last_seq ? nlohmann::ordered_json(*last_seq) : nullptr;
      out["missed"] = missed;
      out["max_size"] = max_size;
      std::printf("%s\n", out.dump().c_str());
      return;
    }
    std::printf(
        "received %llu, corrupt %llu, first_seq %s, last_seq %s, missed %llu, max_size %llu\n",
        static_cast<unsigned long long>(received), static_cast<unsigned long long>(corrupt),
        first_seq ? std::to_string(*first_seq).c_str() : "-",
        last_seq ? std::to_string(*last_seq).c_str() : "-", static_cast<unsigned long long>(missed),
        static_cast<unsigned long long>(max_size));
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Receives and verifies messages from agnocast-talker."};
  std::string topic;
  std::uint64_t count = 0;
  std::size_t depth = 10;
  bool transient_local = false;
  double timeout = 0;
  std::string node_name = "listener";
  bool json = false;
  app.add_option("--topic", topic, "topic to subscribe to")->required();
  app.add_option("--count", count, "exit 0 after this many verified messages (0: never)");
  app.add_option("--depth", depth, "QoS depth");
  app.add_flag("--transient-local", transient_local, "also receive messages kept for late joiners");
  app.add_option("--timeout", timeout, "exit 1 after this many seconds (0: never)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--node", node_name, "node name shown by agnocast-cli");
  app.add_flag("--json", json, "print the summary as one JSON object");
  CLI11_PARSE(app, argc, argv);

  Summary summary;
  try {
    agnocast::Node node{node_name};
    agnocast::QoS qos{depth};
    if (transient_local) qos.transient_local();
    auto subscription = node.create_subscription<chatter::Message>(
        topic, qos, [&](const agnocast::ipc_shared_ptr<const chatter::Message>& message) {
          // One wake-up may deliver a whole batch: stop counting at exactly --count.
          if (count == 0 || summary.received < count) summary.record(*message);
        });
    agnocast::SingleThreadedExecutor executor;
    executor.add_node(node);

    using Clock = std::chrono::steady_clock;
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(timeout));
    while (agnocast::ok() && summary.corrupt == 0 && (count == 0 || summary.verified < count)) {
      if (timeout > 0 && Clock::now() >= deadline) break;
      executor.spin_once(std::chrono::milliseconds(100));
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "agnocast-listener: %s\n", error.what());
    return 1;
  }
  summary.print(json);
  if (summary.corrupt > 0) return 1;
  if (count > 0 && summary.verified < count) return 1;  // timed out or interrupted early
  return 0;
}
