#include "svg_plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <regex>
#include <string>
#include <vector>

namespace agnocast::bench {
namespace {

// One <svg> root holding every element, each closed in order, attribute
// values quoted and free of '<', and every '&' the start of an entity.
testing::AssertionResult WellFormed(const std::string& xml) {
  for (std::size_t at = xml.find('&'); at != std::string::npos; at = xml.find('&', at + 1)) {
    bool entity = false;
    for (const char* name : {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"}) {
      entity = entity || xml.compare(at, std::strlen(name), name) == 0;
    }
    if (!entity) return testing::AssertionFailure() << "a bare & at " << at;
  }
  if (xml.rfind("<svg ", 0) != 0) return testing::AssertionFailure() << "does not start with <svg";
  std::vector<std::string> open;
  bool root_closed = false;
  std::size_t at = 0;
  while ((at = xml.find_first_of("<>", at)) != std::string::npos) {
    if (xml[at] == '>') return testing::AssertionFailure() << "a bare > at " << at;
    if (root_closed) return testing::AssertionFailure() << "a tag after the root at " << at;
    std::size_t end = at + 1;
    for (char quote = 0; end < xml.size() && (quote || xml[end] != '>'); ++end) {
      if (xml[end] == '<') return testing::AssertionFailure() << "a < inside a tag at " << end;
      if (xml[end] == '"') quote = quote ? 0 : '"';
    }
    if (end == xml.size()) return testing::AssertionFailure() << "an unterminated tag at " << at;
    const std::string tag = xml.substr(at + 1, end - at - 1);
    if (tag.starts_with("/")) {
      if (open.empty() || open.back() != tag.substr(1)) {
        return testing::AssertionFailure()
               << "</" << tag.substr(1) << "> closes " << (open.empty() ? "nothing" : open.back());
      }
      open.pop_back();
      root_closed = open.empty();
    } else if (!tag.ends_with("/")) {
      open.push_back(tag.substr(0, tag.find(' ')));
    }
    at = end + 1;
  }
  if (!open.empty()) return testing::AssertionFailure() << "<" << open.back() << "> not closed";
  return testing::AssertionSuccess();
}

struct Position {
  double x = 0;
  double y = 0;
};

// The markers of the measured points, in document order.
std::vector<Position> markers(const std::string& svg) {
  std::vector<Position> found;
  static const std::regex circle(R"re(<circle cx="([-0-9.]+)" cy="([-0-9.]+)")re");
  for (std::sregex_iterator it(svg.begin(), svg.end(), circle), end; it != end; ++it) {
    found.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
  }
  return found;
}

struct Frame {
  double left = 0, top = 0, right = 0, bottom = 0;
};

Frame frame(const std::string& svg) {
  static const std::regex rect(
      R"re(<rect class="frame" x="([0-9.]+)" y="([0-9.]+)" width="([0-9.]+)" height="([0-9.]+)")re");
  std::smatch match;
  if (!std::regex_search(svg, match, rect)) return {};
  const double left = std::stod(match[1]), top = std::stod(match[2]);
  return {left, top, left + std::stod(match[3]), top + std::stod(match[4])};
}

LinePlot plot_of(std::vector<PlotPoint> points, bool log_x = false) {
  LinePlot plot;
  plot.title = "t";
  plot.x_label = "x";
  plot.y_label = "y";
  plot.log_x = log_x;
  plot.lines.push_back({"a", std::move(points), false});
  return plot;
}

TEST(SvgPlot, IsOneWellFormedSvgDocument) {
  LinePlot plot = plot_of({{1, 10}, {2, 30}, {4, 20}}, true);
  plot.lines.push_back({"b", {{1, 5}, {4, 6}}, false});
  plot.lines.push_back({"fit", {{1, 1}, {4, 4}}, true});
  const std::string svg = render_svg(plot);
  EXPECT_TRUE(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\" "));
  EXPECT_TRUE(svg.ends_with("</svg>\n"));
  EXPECT_TRUE(WellFormed(svg)) << svg;
  EXPECT_EQ(markers(svg).size(), 5u) << "a fitted line has no markers";
  EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos);
  EXPECT_EQ(svg.find("<script"), std::string::npos);
  EXPECT_EQ(svg.find("@import"), std::string::npos);
}

TEST(SvgPlot, LargerValuesLieFurtherRightAndHigherInsideTheFrame) {
  const std::string svg = render_svg(plot_of({{40, 7}, {1, 1}, {300, 900}, {2, 3}}));
  const std::vector<Position> at = markers(svg);
  ASSERT_EQ(at.size(), 4u);
  // Drawn from left to right whatever the order given; SVG's y grows downwards.
  for (std::size_t i = 1; i < at.size(); ++i) {
    EXPECT_GT(at[i].x, at[i - 1].x) << i;
    EXPECT_LT(at[i].y, at[i - 1].y) << i;
  }
  const Frame box = frame(svg);
  ASSERT_LT(box.left, box.right);
  for (const Position& point : at) {
    EXPECT_GT(point.x, box.left);
    EXPECT_LT(point.x, box.right);
    EXPECT_GT(point.y, box.top);
    EXPECT_LE(point.y, box.bottom);
  }
}

TEST(SvgPlot, YIsLinearFromZeroWithRoundTicks) {
  const std::string svg = render_svg(plot_of({{1, 11794}, {2, 11796}}));
  for (const char* tick : {">0<", ">2,000<", ">10,000<", ">12,000<"}) {
    EXPECT_NE(svg.find(tick), std::string::npos) << tick;
  }
  EXPECT_EQ(svg.find(">14,000<"), std::string::npos);
  // Two values 0.02 % apart look flat: far from the bottom, close together.
  const std::vector<Position> at = markers(svg);
  ASSERT_EQ(at.size(), 2u);
  EXPECT_LT(std::fabs(at[0].y - at[1].y), 0.5);
  EXPECT_LT(at[0].y, frame(svg).bottom - 200);
}

TEST(SvgPlot, LogAxisSpacesEachDecadeEquallyAndLabelsTheGivenTicks) {
  LinePlot plot = plot_of({{1, 1}, {10, 1}, {100, 1}, {1000, 1}}, true);
  plot.x_ticks = {{1, "one"}, {1000, "1 KiB"}, {1e6, "outside"}};
  const std::string logarithmic = render_svg(plot);
  const std::vector<Position> at = markers(logarithmic);
  ASSERT_EQ(at.size(), 4u);
  const double decade = at[1].x - at[0].x;
  EXPECT_GT(decade, 50);
  EXPECT_NEAR(at[2].x - at[1].x, decade, 0.15);
  EXPECT_NEAR(at[3].x - at[2].x, decade, 0.15);
  EXPECT_NE(logarithmic.find(">one<"), std::string::npos);
  EXPECT_NE(logarithmic.find(">1 KiB<"), std::string::npos);
  EXPECT_EQ(logarithmic.find(">outside<"), std::string::npos);

  plot.log_x = false;
  const std::vector<Position> linear = markers(render_svg(plot));
  ASSERT_EQ(linear.size(), 4u);
  EXPECT_GT(linear[3].x - linear[2].x, 50 * (linear[1].x - linear[0].x));
}

TEST(SvgPlot, LogAxisWithoutGivenTicksLabelsThePowersOfTen) {
  const std::string svg = render_svg(plot_of({{1, 1}, {10000, 1}}, true));
  for (const char* tick : {">1<", ">10<", ">100<", ">1,000<", ">10,000<"}) {
    EXPECT_NE(svg.find(tick), std::string::npos) << tick;
  }
}

TEST(SvgPlot, LinearXEndsAtTheLastPointTickedAtRoundSteps) {
  const std::string svg = render_svg(plot_of({{1, 1}, {64, 2}}));
  for (const char* tick : {">0<", ">20<", ">40<", ">60<"}) {
    EXPECT_NE(svg.find(tick), std::string::npos) << tick;
  }
  EXPECT_EQ(svg.find(">80<"), std::string::npos);
}

TEST(SvgPlot, AnXLabelThatWouldOverlapTheOneBeforeIsLeftOut) {
  LinePlot plot = plot_of({{1, 1}, {1000, 1}}, true);
  plot.x_ticks = {{1, "first label"}, {1.05, "second label"}, {1000, "last"}};
  const std::string svg = render_svg(plot);
  EXPECT_NE(svg.find(">first label<"), std::string::npos);
  EXPECT_EQ(svg.find(">second label<"), std::string::npos);
  EXPECT_NE(svg.find(">last<"), std::string::npos);
}

TEST(SvgPlot, EscapesEveryText) {
  LinePlot plot = plot_of({{1, 1}, {2, 2}});
  plot.title = "a<b & \"c\"";
  plot.x_label = "x > 'y'";
  plot.y_label = "&lt;";
  plot.lines[0].name = "<line>";
  plot.x_ticks = {{1, "<&>"}};
  const std::string svg = render_svg(plot);
  EXPECT_TRUE(WellFormed(svg)) << svg;
  EXPECT_NE(svg.find(">a&lt;b &amp; &quot;c&quot;<"), std::string::npos);
  EXPECT_NE(svg.find(">x &gt; &apos;y&apos;<"), std::string::npos);
  EXPECT_NE(svg.find(">&amp;lt;<"), std::string::npos);
  EXPECT_NE(svg.find(">&lt;line&gt;<"), std::string::npos);
  EXPECT_NE(svg.find(">&lt;&amp;&gt;<"), std::string::npos);
}

TEST(SvgPlot, EmptyOnePointAndUnplaceableSeriesDrawWithoutNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (bool log_x : {false, true}) {
    LinePlot plot = plot_of({{3, 7}}, log_x);
    plot.lines.push_back({"empty", {}, false});
    plot.lines.push_back({"unplaceable", {{nan, 1}, {1, inf}, {-inf, 2}}, false});
    plot.lines.push_back({"zero on a log axis", {{0, 1}, {-5, 1}}, false});
    for (const LinePlot& drawn : {plot, plot_of({}, log_x)}) {
      const std::string svg = render_svg(drawn);
      EXPECT_TRUE(WellFormed(svg)) << svg;
      std::string lower = svg;
      for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      EXPECT_EQ(lower.find("nan"), std::string::npos) << svg;
      EXPECT_EQ(lower.find("inf"), std::string::npos) << svg;
    }
    const std::size_t expected = log_x ? 1 : 3;  // x ≤ 0 is placeable on a linear axis
    EXPECT_EQ(markers(render_svg(plot)).size(), expected) << log_x;
    const std::string one_point = render_svg(plot_of({{3, 7}}, log_x));
    EXPECT_EQ(markers(one_point).size(), 1u);
    EXPECT_EQ(one_point.find("<polyline"), std::string::npos) << "one point is its marker alone";
  }
}

TEST(SvgPlot, SamePlotSameBytes) {
  LinePlot plot = plot_of({{64, 10188.4}, {4096, 10182.1}, {1 << 20, 10187.9}}, true);
  plot.x_ticks = {{64, "64 B"}, {4096, "4 KiB"}, {1 << 20, "1 MiB"}};
  EXPECT_EQ(render_svg(plot), render_svg(LinePlot(plot)));
  LinePlot moved = plot;
  moved.lines[0].points[1].y = 20000;
  EXPECT_NE(render_svg(plot), render_svg(moved));
}

}  // namespace
}  // namespace agnocast::bench
