#include "bag/qos_profiles.hpp"

#include <algorithm>
#include <charconv>

#include "agnocast/limits.hpp"

namespace agnocast::cli {

std::string offered_qos_profiles(const std::vector<std::pair<std::uint32_t, bool>>& publishers) {
  // rosbag2's YAML, with rmw's numbers: history 1 keep last, reliability 1
  // reliable, durability 1 transient local or 2 volatile, liveliness 1
  // automatic; the other policies infinite (rmw's default).
  const std::string infinite = "    sec: 2147483647\n    nsec: 4294967295\n";
  std::string text;
  for (const auto& [depth, transient_local] : publishers) {
    text += "- history: 1\n  depth: " + std::to_string(depth) +
            "\n  reliability: 1\n  durability: " + (transient_local ? "1" : "2") +
            "\n  deadline:\n" + infinite + "  lifespan:\n" + infinite +
            "  liveliness: 1\n  liveliness_lease_duration:\n" + infinite +
            "  avoid_ros_namespace_conventions: false\n";
  }
  return text;
}

namespace {

std::string_view trimmed(std::string_view text) {
  const std::size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  const std::size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

}  // namespace

QoS played_qos(std::string_view profiles, std::size_t default_depth) {
  std::size_t depth = 0;
  bool transient_local = false;
  while (!profiles.empty()) {
    const std::size_t end = profiles.find('\n');
    std::string_view line = profiles.substr(0, end);
    profiles = end == std::string_view::npos ? std::string_view{} : profiles.substr(end + 1);
    line = trimmed(line);
    if (line.starts_with("- ")) line = trimmed(line.substr(2));
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string_view key = trimmed(line.substr(0, colon));
    const std::string_view value = trimmed(line.substr(colon + 1));
    if (key == "durability") {
      // rmw_qos_durability_policy_t: 1 transient local, 2 volatile.
      transient_local = transient_local || value == "1" || value == "transient_local";
    } else if (key == "depth") {
      std::size_t parsed = 0;
      const auto [at, error] = std::from_chars(value.data(), value.data() + value.size(), parsed);
      if (error == std::errc{} && at == value.data() + value.size())
        depth = std::max(depth, parsed);
    }
  }
  // Depth 0 is keep-all (or unknown): the default, as for no profile.
  if (depth == 0) depth = default_depth;
  QoS qos(std::clamp(depth, qos_depth_min, qos_depth_max));
  if (transient_local) qos.transient_local();
  return qos;
}

}  // namespace agnocast::cli
