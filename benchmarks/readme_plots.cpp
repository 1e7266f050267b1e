#include "readme_plots.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "bench_support.hpp"
#include "svg_plot.hpp"

namespace agnocast::bench {
namespace {

using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// A series' labels are counts ("1", "100") or sizes ("64 B", "4 KiB").
enum class Labels { count, size };

struct Series {
  const char* key;
  const char* name;
};

// A plot of latency p50s, one line a series.
struct Spec {
  const char* table;  // the README table it follows, and its file's name
  const char* title;
  const char* x_label;
  Labels labels;
  bool log_x;
  bool both_modes;  // else icount only, whose figures repeat from run to run
  std::vector<Series> series;
};

// In the unit of that mode's tables.
struct Mode {
  const char* name;
  double unit_per_us;
  const char* y_label;
};

const Mode modes[] = {{"icount", 1000, "p50, ns (instructions)"}, {"ordinary", 1, "p50, µs"}};

const Spec specs[] = {
    {"idle_topics",
     "One-way 64 B latency beside idle topics",
     "other topics registered, idle",
     Labels::count,
     true,
     false,
     {{"agnocast_beside_idle_topics", "agnocast"}}},
    {"processes_attached",
     "One-way 64 B latency with processes attached",
     "processes attached in all",
     Labels::count,
     false,
     false,
     {{"agnocast_with_processes_attached", "agnocast"}}},
    {"fanout",
     "Publish to last delivery, 4 KiB",
     "subscribers",
     Labels::count,
     true,
     false,
     {{"agnocast_fanout", "agnocast"}, {"mqueue_fanout", "mqueue wake-ups"}}},
    {"depth",
     "One-way latency and publish() by QoS depth",
     "QoS depth",
     Labels::count,
     true,
     false,
     {{"agnocast_depth", "one-way latency"},
      {"agnocast_publish_taken", "publish(), queue taken"},
      {"agnocast_publish_into_full_queue", "publish(), queue full"}}},
    {"sizes",
     "One-way latency, 64 MiB written before each sample",
     "payload",
     Labels::size,
     true,
     true,
     {{"agnocast_constant_bytes", "agnocast"},
      {"iceoryx_constant_bytes", "iceoryx"},
      {"unix_socket_constant_bytes", "Unix socket (copy)"}}},
    {"service_sizes",
     "Service request → response round trip",
     "payload, each way",
     Labels::size,
     true,
     false,
     {{"agnocast_service", "agnocast service"}}},
};

// The member, or null when the object lacks it.
const json& member(const json& object, const char* key) {
  static const json null_value;
  return object.is_object() && object.contains(key) ? object[key] : null_value;
}

double label_x(const std::string& label, Labels labels) {
  return labels == Labels::size ? static_cast<double>(size_label_bytes(label)) : std::stod(label);
}

// Titled with its mode; no lines yet.
LinePlot plot_in(const Mode& mode, const char* title, const char* x_label, bool log_x) {
  LinePlot plot;
  plot.title = std::string(title) + " (" + mode.name + " mode)";
  plot.x_label = x_label;
  plot.y_label = mode.y_label;
  plot.log_x = log_x;
  return plot;
}

// Each series' p50 by label; the x axis labelled where they were measured.
LinePlot latency_plot(const json& report, const Spec& spec, const Mode& mode) {
  LinePlot plot = plot_in(mode, spec.title, spec.x_label, spec.log_x);
  std::map<double, std::string> measured_at;
  for (const Series& series : spec.series) {
    PlotLine line;
    line.name = series.name;
    for (const auto& [label, stats] : member(member(report, "latency"), series.key).items()) {
      const json& p50 = member(stats, "p50_us");
      if (!p50.is_number()) continue;
      const double x = label_x(label, spec.labels);
      line.points.push_back({x, p50.get<double>() * mode.unit_per_us});
      measured_at.emplace(x, label);
    }
    plot.lines.push_back(std::move(line));
  }
  // A linear axis gets round numbers instead: measured points crowd at its low end.
  if (spec.log_x) {
    for (const auto& [x, label] : measured_at) plot.x_ticks.push_back({x, label});
  }
  return plot;
}

// The publisher's own CPU time in publish() by subscribers woken, and the
// line fitted to it: linear axes, so that a straight line reads as linear.
LinePlot publish_call_plot(const json& report, const Mode& mode) {
  LinePlot plot = plot_in(mode, "Publisher's CPU time in publish()", "subscribers woken", false);
  PlotLine measured;
  measured.name = "measured";
  const json& calls = member(member(report, "send_call"), "agnocast_fanout");
  for (const auto& [label, call] : calls.items()) {
    const json& cpu = member(call, "cpu_p50_us");
    if (cpu.is_number()) {
      measured.points.push_back({std::stod(label), cpu.get<double>() * mode.unit_per_us});
    }
  }
  // Drawn over the measured points' range; left out (as empty) without a fit.
  PlotLine fitted;
  fitted.fitted = true;
  const json& fit = member(report, "publish_call_us");
  const json& base = member(fit, "base");
  const json& slope = member(fit, "per_subscriber");
  if (base.is_number() && slope.is_number()) {
    const double b = base.get<double>() * mode.unit_per_us;
    const double s = slope.get<double>() * mode.unit_per_us;
    char name[64];
    std::snprintf(name, sizeof name, "fit: %.0f + %.0f × n", b, s);
    fitted.name = name;
    for (const auto& point : measured.points) fitted.points.push_back({point.x, b + s * point.x});
  }
  plot.lines.push_back(std::move(measured));
  plot.lines.push_back(std::move(fitted));
  return plot;
}

}  // namespace

std::size_t size_label_bytes(std::string label) {
  // parse_size reads "64" and "4KiB": drop the space and a bare "B".
  std::erase(label, ' ');
  if (label.size() > 1 && label.back() == 'B' &&
      std::isdigit(static_cast<unsigned char>(label[label.size() - 2]))) {
    label.pop_back();
  }
  return parse_size(label);
}

std::map<std::string, PlotLinks> write_readme_plots(const json& combined, const fs::path& folder) {
  fs::create_directories(folder);
  const fs::path named = folder.has_filename() ? folder : folder.parent_path();
  const std::string prefix = named.filename().string() + "/";
  std::map<std::string, PlotLinks> links;
  auto write = [&](const Mode& mode, const std::string& table, const std::string& file,
                   LinePlot plot) {
    std::erase_if(plot.lines, [](const PlotLine& line) { return line.points.empty(); });
    const fs::path path = folder / file;
    if (plot.lines.empty()) {
      fs::remove(path);
      return;
    }
    std::ofstream out(path, std::ios::binary);
    out << render_svg(plot);
    if (!out.flush()) throw std::runtime_error(path.string() + ": cannot write");
    links[mode.name][table] = "![" + plot.title + "](" + prefix + file + ")";
  };
  for (const Mode& mode : modes) {
    const json& report = member(combined, mode.name);
    const bool icount = mode.name == std::string("icount");
    for (const Spec& spec : specs) {
      if (!icount && !spec.both_modes) continue;
      const std::string file =
          std::string(spec.table) + (spec.both_modes ? std::string("_") + mode.name : "") + ".svg";
      write(mode, spec.table, file, latency_plot(report, spec, mode));
    }
    if (icount) write(mode, "publish_call", "publish_call.svg", publish_call_plot(report, mode));
  }
  return links;
}

}  // namespace agnocast::bench
