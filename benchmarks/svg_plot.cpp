#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>

namespace agnocast::bench {
namespace {

// The canvas in SVG units: the frame (the box the axes draw) with the tick
// labels left of and below it, and the legend to its right.
constexpr double width = 840, height = 420;
constexpr double frame_left = 110, frame_right = 650, frame_top = 46, frame_bottom = 350;
// Points stay this far inside the frame's sides and top, so that no marker
// sits on the box.
constexpr double inset = 12;
constexpr const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};

std::string escaped(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// One decimal, the C locale's point (nothing here calls setlocale): the
// same coordinate is always the same text.
std::string coordinate(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value);
  return text;
}

// With as many decimals as `step` needs, and thousands separated by commas
// as in the README's text ("10,000").
std::string tick_label(double value, double step) {
  if (std::fabs(value) < step * 1e-6) value = 0;  // no "-0"
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  std::string digits = text;
  const std::size_t sign = digits[0] == '-' ? 1 : 0;
  std::size_t point = digits.find('.');
  if (point == std::string::npos) point = digits.size();
  std::string grouped = digits.substr(0, sign);
  for (std::size_t at = sign; at < point; ++at) {
    if (at > sign && (point - at) % 3 == 0) grouped += ',';
    grouped += digits[at];
  }
  grouped.append(digits, point, std::string::npos);
  return grouped;
}

// 1, 2 or 5 times a power of ten, about `count` of them over `span`.
double nice_step(double span, int count) {
  const double raw = span / count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 5.0}) {
    if (raw <= factor * magnitude * (1 + 1e-9)) return factor * magnitude;
  }
  return 10 * magnitude;
}

// Data values onto canvas positions, `from` for `low` and `to` for `high`.
struct Axis {
  bool log = false;
  double low = 0, high = 1;
  double from = 0, to = 1;
  std::vector<PlotTick> ticks;

  double at(double value) const {
    const double share =
        log ? std::log10(value / low) / std::log10(high / low) : (value - low) / (high - low);
    return from + share * (to - from);
  }
};

// From 0 (or the lowest value, if negative) to the highest, or to a round
// number at or above it, ticked at round steps.
Axis linear_axis(double lowest, double highest, bool round_high) {
  Axis axis;
  axis.low = std::min(0.0, lowest);
  axis.high = std::max(highest, axis.low);
  if (axis.high <= axis.low) axis.high = axis.low + 1;
  const double step = nice_step(axis.high - axis.low, 6);
  axis.low = std::floor(axis.low / step) * step;
  if (round_high) axis.high = std::ceil(axis.high / step) * step;
  const long steps = std::lround(std::floor((axis.high - axis.low) / step + 1e-9));
  for (long i = 0; i <= steps; ++i) {
    const double value = axis.low + static_cast<double>(i) * step;
    axis.ticks.push_back({value, tick_label(value, step)});
  }
  return axis;
}

// From the lowest value to the highest (a decade either side of a single
// value), ticked at the powers of ten between, or at both ends if none.
Axis log_axis(double lowest, double highest) {
  Axis axis;
  axis.log = true;
  axis.low = lowest;
  axis.high = highest;
  if (axis.high <= axis.low) {
    axis.low /= 10;
    axis.high *= 10;
  }
  for (double power = std::pow(10.0, std::ceil(std::log10(axis.low) - 1e-9));
       power <= axis.high * (1 + 1e-9); power *= 10) {
    axis.ticks.push_back({power, tick_label(power, std::min(power, 1.0))});
  }
  if (axis.ticks.size() < 2) {
    axis.ticks = {{axis.low, tick_label(axis.low, std::min(axis.low, 1.0))},
                  {axis.high, tick_label(axis.high, std::min(axis.high, 1.0))}};
  }
  return axis;
}

// About as wide as 12-unit sans-serif text draws: 7 units a character
// (UTF-8 continuation bytes are not characters).
double label_width(std::string_view text) {
  const auto characters =
      std::count_if(text.begin(), text.end(), [](char c) { return (c & 0xc0) != 0x80; });
  return 7 * static_cast<double>(characters);
}

std::string text_element(double x, double y, const char* anchor, std::string_view text,
                         std::string_view extra = "") {
  std::string out = "<text x=\"" + coordinate(x) + "\" y=\"" + coordinate(y) + "\" text-anchor=\"" +
                    anchor + "\"";
  if (!extra.empty()) {
    out += ' ';
    out += extra;
  }
  return out + ">" + escaped(text) + "</text>\n";
}

std::string line_element(double x1, double y1, double x2, double y2, std::string_view style) {
  return "<line x1=\"" + coordinate(x1) + "\" y1=\"" + coordinate(y1) + "\" x2=\"" +
         coordinate(x2) + "\" y2=\"" + coordinate(y2) + "\" " + std::string(style) + "/>\n";
}

}  // namespace

std::string render_svg(const LinePlot& plot) {
  // Only the points that can be placed, each line drawn from left to right.
  std::vector<PlotLine> lines = plot.lines;
  for (auto& line : lines) {
    std::erase_if(line.points, [&](const PlotPoint& point) {
      return !std::isfinite(point.x) || !std::isfinite(point.y) || (plot.log_x && point.x <= 0);
    });
    std::stable_sort(line.points.begin(), line.points.end(),
                     [](const PlotPoint& a, const PlotPoint& b) { return a.x < b.x; });
  }
  constexpr double none = std::numeric_limits<double>::infinity();
  double x_lowest = none, x_highest = -none, y_lowest = none, y_highest = -none;
  for (const auto& line : lines) {
    for (const auto& point : line.points) {
      x_lowest = std::min(x_lowest, point.x);
      x_highest = std::max(x_highest, point.x);
      y_lowest = std::min(y_lowest, point.y);
      y_highest = std::max(y_highest, point.y);
    }
  }
  if (x_lowest > x_highest) {  // nothing to place: an empty frame
    x_lowest = 1;
    x_highest = plot.log_x ? 10 : 1;
    y_lowest = y_highest = 0;
  }

  // x ends at the last point, y at a round number above the highest.
  Axis x = plot.log_x ? log_axis(x_lowest, x_highest) : linear_axis(x_lowest, x_highest, false);
  x.from = frame_left + inset;
  x.to = frame_right - inset;
  if (!plot.x_ticks.empty()) {
    x.ticks.clear();
    for (const auto& tick : plot.x_ticks) {
      const bool placeable = std::isfinite(tick.x) && (!plot.log_x || tick.x > 0);
      if (placeable && tick.x >= x.low && tick.x <= x.high) x.ticks.push_back(tick);
    }
  }
  Axis y = linear_axis(y_lowest, y_highest, true);
  y.from = frame_bottom;
  y.to = frame_top + inset;

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + coordinate(width) +
                    "\" height=\"" + coordinate(height) + "\" viewBox=\"0 0 " + coordinate(width) +
                    " " + coordinate(height) +
                    "\" font-family=\"sans-serif\" font-size=\"12\" fill=\"#222\">\n";
  // An opaque background: readable on a dark page too.
  svg += "<rect x=\"0\" y=\"0\" width=\"" + coordinate(width) + "\" height=\"" +
         coordinate(height) + "\" fill=\"#fff\"/>\n";
  svg += text_element(width / 2, 26, "middle", plot.title, "font-size=\"15\" font-weight=\"bold\"");

  for (const auto& tick : y.ticks) {
    const double at = y.at(tick.x);
    svg += line_element(frame_left, at, frame_right, at, "stroke=\"#e4e4e4\"");
    svg += text_element(frame_left - 8, at + 4, "end", tick.label);
  }
  // A label that would overlap the one before it is left out; its tick stays.
  double labelled_up_to = -none;
  for (const auto& tick : x.ticks) {
    const double at = x.at(tick.x);
    svg += line_element(at, frame_top, at, frame_bottom, "stroke=\"#f0f0f0\"");
    svg += line_element(at, frame_bottom, at, frame_bottom + 5, "stroke=\"#444\"");
    const double half = label_width(tick.label) / 2;
    if (at - half < labelled_up_to + 4) continue;
    svg += text_element(at, frame_bottom + 19, "middle", tick.label);
    labelled_up_to = at + half;
  }
  svg += "<rect class=\"frame\" x=\"" + coordinate(frame_left) + "\" y=\"" + coordinate(frame_top) +
         "\" width=\"" + coordinate(frame_right - frame_left) + "\" height=\"" +
         coordinate(frame_bottom - frame_top) + "\" fill=\"none\" stroke=\"#444\"/>\n";
  svg += text_element((frame_left + frame_right) / 2, frame_bottom + 44, "middle", plot.x_label,
                      "font-size=\"13\"");
  const double y_label_x = 18, y_label_y = (frame_top + frame_bottom) / 2;
  svg += text_element(y_label_x, y_label_y, "middle", plot.y_label,
                      "font-size=\"13\" transform=\"rotate(-90 " + coordinate(y_label_x) + " " +
                          coordinate(y_label_y) + ")\"");

  auto color = [](std::size_t i) { return std::string(colors[i % std::size(colors)]); };
  auto dash = [&](std::size_t i) {
    return std::string(lines[i].fitted ? " stroke-dasharray=\"6 4\"" : "");
  };
  // Last to first: where lines coincide, the first one named is the one seen.
  for (std::size_t i = lines.size(); i-- > 0;) {
    const PlotLine& line = lines[i];
    if (line.points.size() >= 2) {
      svg += "<polyline fill=\"none\" stroke=\"" + color(i) + "\" stroke-width=\"2\"" + dash(i) +
             " points=\"";
      for (std::size_t p = 0; p < line.points.size(); ++p) {
        if (p) svg += ' ';
        svg += coordinate(x.at(line.points[p].x));
        svg += ',';
        svg += coordinate(y.at(line.points[p].y));
      }
      svg += "\"/>\n";
    }
    if (!line.fitted) {
      for (const auto& point : line.points) {
        svg += "<circle cx=\"" + coordinate(x.at(point.x)) + "\" cy=\"" +
               coordinate(y.at(point.y)) + "\" r=\"3.5\" fill=\"" + color(i) + "\"/>\n";
      }
    }
  }
  // The legend, one row a line, right of the frame.
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const double row = frame_top + 8 + 22 * static_cast<double>(i);
    svg += line_element(frame_right + 16, row, frame_right + 40, row,
                        "stroke=\"" + color(i) + "\" stroke-width=\"2\"" + dash(i));
    svg += text_element(frame_right + 46, row + 4, "start", lines[i].name);
  }
  return svg + "</svg>\n";
}

}  // namespace agnocast::bench
