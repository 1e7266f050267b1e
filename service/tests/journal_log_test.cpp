#include "agnocast_service/journal_log.hpp"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <sstream>

namespace agnocast_service {
namespace {

std::string logged_in_format(bool to_journal, LogStyle style = LogStyle::timestamped) {
  std::ostringstream out;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_st>(out);
  spdlog::logger logger("test", sink);
  logger.set_formatter(log_formatter(to_journal, style, "prog%"));
  logger.set_level(spdlog::level::trace);
  logger.critical("c");
  logger.error("e");
  logger.warn("w");
  logger.info("i");
  logger.debug("d");
  return out.str();
}

TEST(JournalLog, EachLineStartsWithItsSyslogPriority) {
  EXPECT_EQ(logged_in_format(true), "<2>c\n<3>e\n<4>w\n<6>i\n<7>d\n");
}

TEST(JournalLog, OutsideTheJournalLinesNameTheirLevel) {
  const std::string text = logged_in_format(false);
  EXPECT_EQ(text.find('<'), std::string::npos);
  EXPECT_NE(text.find("] [error] e\n"), std::string::npos);
  EXPECT_NE(text.find("] [warning] w\n"), std::string::npos);
}

TEST(JournalLog, TaggedLinesStartWithTheProgramsName) {
  EXPECT_EQ(logged_in_format(false, LogStyle::tagged),
            "prog%: c\nprog%: e\nprog%: w\nprog%: i\nprog%: d\n");
  // In the journal, which names the program itself, as any other style.
  EXPECT_EQ(logged_in_format(true, LogStyle::tagged), "<2>c\n<3>e\n<4>w\n<6>i\n<7>d\n");
}

TEST(JournalLog, StderrIsTheJournalOnlyWhenJournalStreamNamesIt) {
  ::unsetenv("JOURNAL_STREAM");
  EXPECT_FALSE(stderr_is_journal());
  ::setenv("JOURNAL_STREAM", "1:2", 1);
  EXPECT_FALSE(stderr_is_journal());
  ::unsetenv("JOURNAL_STREAM");
}

}  // namespace
}  // namespace agnocast_service
