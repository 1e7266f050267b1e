#include "agnocast_service/journal_log.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace agnocast_service {
namespace {

// The "%*" pattern flag: "<N>", the record's syslog priority.
class SyslogPriorityFlag : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& message, const std::tm&,
              spdlog::memory_buf_t& destination) override {
    // Priorities are single digits; no std::string, whose concatenation
    // GCC 12 at -O3 flags with a false -Wrestrict.
    const char prefix[] = {'<', static_cast<char>('0' + syslog_priority(message.level)), '>'};
    destination.append(prefix, prefix + sizeof(prefix));
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<SyslogPriorityFlag>();
  }
};

// A pattern that prints text as it is ('%' is the pattern's escape).
std::string literal_pattern(const std::string& text) {
  std::string pattern;
  for (const char c : text) {
    if (c == '%') pattern += '%';
    pattern += c;
  }
  return pattern;
}

}  // namespace

bool stderr_is_journal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  unsigned long long device = 0;
  unsigned long long inode = 0;
  if (std::sscanf(stream, "%llu:%llu", &device, &inode) != 2) return false;
  struct stat status {};
  if (::fstat(STDERR_FILENO, &status) != 0) return false;
  return status.st_dev == device && status.st_ino == inode;
}

int syslog_priority(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::critical:
      return 2;
    case spdlog::level::err:
      return 3;
    case spdlog::level::warn:
      return 4;
    case spdlog::level::info:
      return 6;
    default:
      return 7;
  }
}

std::unique_ptr<spdlog::formatter> log_formatter(bool to_journal, LogStyle style,
                                                 const std::string& program) {
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  // journald stamps each line itself, names the program and reads the
  // priority from "<N>".
  std::string pattern = "%*%v";
  if (!to_journal) {
    pattern =
        style == LogStyle::tagged ? literal_pattern(program) + ": %v" : "[%Y-%m-%d %T.%e] [%l] %v";
  }
  formatter->add_flag<SyslogPriorityFlag>('*').set_pattern(pattern);
  return formatter;
}

void set_up_logging(const std::string& program, const std::string& level, bool to_journal,
                    LogStyle style) {
  auto logger = spdlog::stderr_logger_mt(program);
  logger->set_formatter(log_formatter(to_journal, style, program));
  logger->set_level(spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::trace);
  spdlog::set_default_logger(logger);
}

}  // namespace agnocast_service
