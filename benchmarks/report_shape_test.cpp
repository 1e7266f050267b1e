#include "report_shape.hpp"

#include <gtest/gtest.h>

#include <string>

namespace agnocast::bench {
namespace {

using json = nlohmann::ordered_json;

// One run of the tracing-cost series: the two ioctls of the cost breakdown
// and agnocast's one-way p50s, in ns.
json tracing_run(double publish_ns, double receive_ns, double small_ns, double large_ns) {
  json run;
  run["cost_breakdown"]["publisher"]["calls"] =
      json::array({{{"name", "ioctl PUBLISH"}, {"ns", publish_ns}}});
  run["cost_breakdown"]["subscriber"]["calls"] =
      json::array({{{"name", "ioctl RECEIVE"}, {"ns", receive_ns}}});
  run["latency"]["agnocast"]["64 B"]["p50_us"] = small_ns / 1000;
  run["latency"]["agnocast"]["4 KiB"]["p50_us"] = large_ns / 1000;
  return run;
}

std::string tracing_cost_section(const json& combined) {
  testing::internal::CaptureStdout();
  print_tracing_cost(combined);
  return testing::internal::GetCapturedStdout();
}

TEST(TracingCost, EachColumnIsAgainstTheNextAndWithinOnePercentIsMet) {
  json combined;
  combined["tracing_cost"]["traced"] = tracing_run(1010, 2000, 10000, 20000);
  combined["tracing_cost"]["module_untraced"] = tracing_run(1000, 2000, 9950, 20000);
  combined["tracing_cost"]["untraced"] = tracing_run(1000, 2000, 9950, 19900);
  combined["icount"]["latency"]["agnocast"]["64 B"]["p50_us"] = 10.1;
  const std::string section = tracing_cost_section(combined);
  EXPECT_NE(section.find("| `ioctl` PUBLISH | 1010 | 1000 | 1000 | +1.00 % | +0.00 % |"),
            std::string::npos)
      << section;
  EXPECT_NE(section.find("| agnocast one way, 4 KiB, p50 | 20000 | 20000 | 19900 | +0.00 % | "
                         "+0.50 % |"),
            std::string::npos)
      << section;
  // The same build's p50 earlier in the boot, against the first column.
  EXPECT_NE(section.find("was 10100; the first column's is -0.99 % against it"), std::string::npos)
      << section;
  EXPECT_NE(section.find("at most 1 %: **met**\n- libagnocast's"), std::string::npos) << section;
  EXPECT_NE(section.find("cost the one way at most 1 %: **met**\n"), std::string::npos) << section;
}

TEST(TracingCost, MoreThanOnePercentIsNotMet) {
  json combined;
  combined["tracing_cost"]["traced"] = tracing_run(1000, 2050, 10000, 20000);
  combined["tracing_cost"]["module_untraced"] = tracing_run(1000, 2000, 10000, 20000);
  combined["tracing_cost"]["untraced"] = tracing_run(1000, 2000, 9800, 20000);
  const std::string section = tracing_cost_section(combined);
  EXPECT_NE(section.find("+2.50 %"), std::string::npos) << section;
  EXPECT_NE(section.find("PUBLISH, RECEIVE and the one way at most 1 %: **not met**"),
            std::string::npos)
      << section;
  EXPECT_NE(section.find("cost the one way at most 1 %: **not met**"), std::string::npos)
      << section;
  // Without the earlier p50 there is nothing to set the noise by.
  EXPECT_EQ(section.find("earlier in this boot"), std::string::npos) << section;
}

TEST(TracingCost, AMissingRunShowsAsADashAndIsNotMeasured) {
  json combined;
  combined["tracing_cost"]["traced"] = tracing_run(1000, 2000, 10000, 20000);
  combined["tracing_cost"]["untraced"] = tracing_run(1000, 2000, 10000, 20000);
  const std::string section = tracing_cost_section(combined);
  EXPECT_NE(section.find("| `ioctl` RECEIVE | 2000 | — | 2000 | — | — |"), std::string::npos)
      << section;
  EXPECT_NE(section.find("PUBLISH, RECEIVE and the one way at most 1 %: not measured"),
            std::string::npos)
      << section;
}

TEST(TracingCost, AReportWithoutItHasNoSection) {
  EXPECT_EQ(tracing_cost_section(json::object()), "");
  EXPECT_EQ(tracing_cost_section(json{{"tracing_cost", "no"}}), "");
}

}  // namespace
}  // namespace agnocast::bench
