// A line plot as a standalone SVG document: the README's pictures, drawn by
// the program that writes the README, from the same report as its tables.
#pragma once

#include <string>
#include <vector>

namespace agnocast::bench {

struct PlotPoint {
  double x = 0;
  double y = 0;
};

struct PlotLine {
  std::string name;
  std::vector<PlotPoint> points;
  // Drawn dashed and without markers: a line fitted to the measurements,
  // not measurements.
  bool fitted = false;
};

struct PlotTick {
  double x = 0;
  std::string label;
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  // Series measured at 1, 10, 100, ... or 64 B to 64 MiB read best on a
  // logarithmic x axis; y is always linear from 0.
  bool log_x = false;
  // Where the x axis is labelled, e.g. at the measured sizes with their
  // names ("64 B", "4 KiB"); empty: round numbers.
  std::vector<PlotTick> x_ticks;
  std::vector<PlotLine> lines;
};

// The plot at a fixed size, with its title, axes, tick labels and legend.
// Points that cannot be placed (not finite, or x ≤ 0 on a logarithmic axis)
// are left out.  The same plot always gives the same bytes, so writing the
// README again changes a picture only when its numbers change.
std::string render_svg(const LinePlot& plot);

}  // namespace agnocast::bench
