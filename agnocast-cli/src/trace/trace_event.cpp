#include "trace/trace_event.hpp"

#include <cctype>
#include <charconv>

namespace agnocast::cli {
namespace {

std::optional<std::int64_t> to_integer(std::string_view value) {
  int base = 10;
  if (value.starts_with("0x") || value.starts_with("0X")) {
    value.remove_prefix(2);
    base = 16;
  }
  std::int64_t result = 0;
  const char* end = value.data() + value.size();
  const auto [stop, error] = std::from_chars(value.data(), end, result, base);
  if (value.empty() || error != std::errc() || stop != end) {
    // A hex value above INT64_MAX (an address) still names something.
    std::uint64_t unsigned_result = 0;
    const auto [stop2, error2] = std::from_chars(value.data(), end, unsigned_result, base);
    if (value.empty() || error2 != std::errc() || stop2 != end) return std::nullopt;
    return static_cast<std::int64_t>(unsigned_result);
  }
  return result;
}

// Splits "lines" without copying.
template <class Visit>
void for_each_line(std::string_view text, Visit visit) {
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    visit(text.substr(0, end));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
}

// Reads `key = value` pairs, values separated by ", " and braces, strings in
// double quotes (with backslash escapes).
void read_lttng_fields(std::string_view rest, TraceEvent& event) {
  std::size_t at = 0;
  while (at < rest.size()) {
    while (at < rest.size() &&
           (rest[at] == ' ' || rest[at] == ',' || rest[at] == '{' || rest[at] == '}')) {
      ++at;
    }
    const std::size_t key_end = rest.find(" = ", at);
    if (key_end == std::string_view::npos) return;
    const std::string key(rest.substr(at, key_end - at));
    at = key_end + 3;
    std::string value;
    if (at < rest.size() && rest[at] == '"') {
      for (++at; at < rest.size() && rest[at] != '"'; ++at) {
        if (rest[at] == '\\' && at + 1 < rest.size()) ++at;
        value += rest[at];
      }
      ++at;
    } else {
      const std::size_t end = rest.find_first_of(",} ", at);
      value = std::string(rest.substr(at, end == std::string_view::npos ? end : end - at));
      at = end == std::string_view::npos ? rest.size() : end;
    }
    event.fields[key] = std::move(value);
  }
}

}  // namespace

std::optional<std::int64_t> TraceEvent::number(std::string_view key) const {
  const auto found = fields.find(key);
  if (found == fields.end()) return std::nullopt;
  return to_integer(found->second);
}

std::string TraceEvent::text(std::string_view key) const {
  const auto found = fields.find(key);
  return found == fields.end() ? std::string() : found->second;
}

std::vector<TraceEvent> parse_lttng_text(std::string_view text) {
  std::vector<TraceEvent> events;
  for_each_line(text, [&](std::string_view line) {
    // [CYCLES] HOST agnocast:EVENT: { cpu_id = N }, { vpid = .. }, { fields }
    if (!line.starts_with('[')) return;
    const std::size_t close = line.find(']');
    const std::size_t provider = line.find(" agnocast:");
    if (close == std::string_view::npos || provider == std::string_view::npos) return;
    const auto time = to_integer(line.substr(1, close - 1));
    const std::size_t name_start = provider + 10;
    const std::size_t name_end = line.find(": ", name_start);
    if (!time || name_end == std::string_view::npos) return;
    TraceEvent event;
    event.time_ns = *time;
    event.name = std::string(line.substr(name_start, name_end - name_start));
    read_lttng_fields(line.substr(name_end + 2), event);
    const auto pid = event.number("vpid");
    const auto tid = event.number("vtid");
    if (!pid || !tid) return;  // recorded without the contexts: no track to put it on
    event.pid = static_cast<int>(*pid);
    event.tid = static_cast<int>(*tid);
    event.process = event.text("procname");
    events.push_back(std::move(event));
  });
  return events;
}

std::vector<TraceEvent> parse_tracefs_text(std::string_view text) {
  static constexpr std::string_view names[] = {"publish", "receive", "release",     "drop",
                                               "shed",    "reclaim", "process_exit"};
  std::vector<TraceEvent> events;
  for_each_line(text, [&](std::string_view line) {
    //   COMM-TID [CPU] FLAGS SECONDS.MICROS: EVENT: key=value ...
    if (line.starts_with('#')) return;
    const std::size_t cpu = line.find(" [");
    const std::size_t colon = line.find(": ", cpu == std::string_view::npos ? 0 : cpu);
    if (cpu == std::string_view::npos || colon == std::string_view::npos) return;
    const std::size_t name_end = line.find(": ", colon + 2);
    if (name_end == std::string_view::npos) return;
    const std::string_view name = line.substr(colon + 2, name_end - colon - 2);
    bool known = false;
    for (const std::string_view candidate : names) known = known || name == candidate;
    if (!known) return;
    // The timestamp: the last word before the colon.
    const std::size_t time_start = line.rfind(' ', colon) + 1;
    const std::string_view time = line.substr(time_start, colon - time_start);
    const std::size_t dot = time.find('.');
    const auto seconds = to_integer(time.substr(0, dot));
    const auto micros = dot == std::string_view::npos ? std::optional<std::int64_t>(0)
                                                      : to_integer(time.substr(dot + 1));
    // The task: "COMM-TID", COMM may hold dashes and spaces.
    std::string_view task = line.substr(0, cpu);
    while (!task.empty() && task.front() == ' ') task.remove_prefix(1);
    while (!task.empty() && task.back() == ' ') task.remove_suffix(1);
    const std::size_t dash = task.rfind('-');
    const auto tid =
        dash == std::string_view::npos ? std::nullopt : to_integer(task.substr(dash + 1));
    if (!seconds || !micros || !tid) return;
    TraceEvent event;
    event.time_ns = *seconds * 1'000'000'000 + *micros * 1'000;
    event.tid = static_cast<int>(*tid);
    event.process = std::string(task.substr(0, dash));
    event.name = std::string(name);
    std::string_view rest = line.substr(name_end + 2);
    while (!rest.empty()) {
      const std::size_t end = rest.find(' ');
      const std::string_view pair = rest.substr(0, end);
      const std::size_t equals = pair.find('=');
      if (equals != std::string_view::npos) {
        event.fields[std::string(pair.substr(0, equals))] = std::string(pair.substr(equals + 1));
      }
      if (end == std::string_view::npos) break;
      rest.remove_prefix(end + 1);
    }
    event.pid = static_cast<int>(event.number("pid").value_or(event.tid));
    events.push_back(std::move(event));
  });
  return events;
}

}  // namespace agnocast::cli
