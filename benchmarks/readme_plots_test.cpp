#include "readme_plots.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>

#include "bench_support.hpp"

namespace agnocast::bench {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

TEST(ReadmePlots, SizeLabelsReadBackWhatFormatSizeWrites) {
  for (std::size_t bytes : {std::size_t{1}, std::size_t{64}, std::size_t{4096},
                            std::size_t{1} << 20, std::size_t{64} << 20, std::size_t{1000}}) {
    EXPECT_EQ(size_label_bytes(format_size(bytes)), bytes) << format_size(bytes);
  }
  EXPECT_THROW(size_label_bytes("4 XB"), std::invalid_argument);
  EXPECT_THROW(size_label_bytes("B"), std::invalid_argument);
  EXPECT_THROW(size_label_bytes(""), std::invalid_argument);
}

class ReadmePlotsFolder : public testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("agnocast-readme-plots-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    folder_ = root_ / "plots";
  }
  void TearDown() override { fs::remove_all(root_); }

  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder_)) {
      names.insert(entry.path().filename().string());
    }
    return names;
  }

  fs::path root_, folder_;
};

TEST_F(ReadmePlotsFolder, WritesAndLinksOnlyThePlotsWhoseSeriesTheReportHolds) {
  const json combined = json::parse(R"({
    "icount": {"latency": {"agnocast_fanout": {"1": {"p50_us": 12.7}, "64": {"p50_us": 903.4}},
                           "agnocast": {"64 B": {"p50_us": 10.2}}}},
    "ordinary": {"latency": {"iceoryx_constant_bytes": {"64 B": {"p50_us": 80},
                                                        "64 MiB": {"p50_us": 900}}}}
  })");
  // A plot of an earlier report whose series this one lacks.
  fs::create_directories(folder_);
  std::ofstream(folder_ / "depth.svg") << "<svg/>";

  const auto links = write_readme_plots(combined, folder_);

  EXPECT_EQ(files(), (std::set<std::string>{"fanout.svg", "sizes_ordinary.svg"}));
  ASSERT_EQ(links.size(), 2u);
  EXPECT_EQ(links.at("icount"),
            (PlotLinks{{"fanout",
                        "![Publish to last delivery, 4 KiB (icount mode)](plots/"
                        "fanout.svg)"}}));
  EXPECT_EQ(links.at("ordinary"),
            (PlotLinks{{"sizes",
                        "![One-way latency, 64 MiB written before each sample "
                        "(ordinary mode)](plots/sizes_ordinary.svg)"}}));
  std::ifstream fanout(folder_ / "fanout.svg");
  const std::string svg{std::istreambuf_iterator<char>(fanout), {}};
  EXPECT_TRUE(svg.starts_with("<svg "));
  EXPECT_NE(svg.find(">64<"), std::string::npos) << "the x axis is labelled where measured";
  EXPECT_NE(svg.find("ns (instructions)"), std::string::npos);
}

TEST_F(ReadmePlotsFolder, PublishCallPlotHasTheMeasuredPointsAndTheFit) {
  const json combined = json::parse(R"({"icount": {
    "send_call": {"agnocast_fanout": {"1": {"cpu_p50_us": 5.4}, "2": {"cpu_p50_us": 9.3}}},
    "publish_call_us": {"base": 1.4, "per_subscriber": 3.9}}})");
  const auto links = write_readme_plots(combined, folder_.string() + "/");
  EXPECT_EQ(links.at("icount").at("publish_call"),
            "![Publisher's CPU time in publish() (icount mode)](plots/publish_call.svg)");
  std::ifstream file(folder_ / "publish_call.svg");
  const std::string svg{std::istreambuf_iterator<char>(file), {}};
  EXPECT_NE(svg.find("fit: 1400 + 3900 × n"), std::string::npos) << svg;
}

TEST_F(ReadmePlotsFolder, AReportWithoutModesHasNoPlots) {
  EXPECT_TRUE(write_readme_plots(json::object(), folder_).empty());
  EXPECT_TRUE(files().empty());
}

}  // namespace
}  // namespace agnocast::bench
