// A daemon's log (spdlog's default logger): stderr, which systemd hands to
// journald. There each line starts with its syslog priority ("<3>" for an
// error), which journald strips and records, so `journalctl -p err` finds the
// errors; elsewhere each line carries a timestamp and the level's name
// (LogStyle::timestamped) or the program's name (LogStyle::tagged, as a
// command-line tool prints).
//
//   agnocast_service::set_up_logging("x", "info", agnocast_service::stderr_is_journal());
//   spdlog::error("cannot open {}", path);  // journal "<3>cannot open ..."
//                                           // terminal "[2026-01-01 10:00:00.000] [error] cannot
//                                           open ..."
#pragma once

#include <spdlog/formatter.h>

#include <memory>
#include <string>

namespace agnocast_service {

enum class LogStyle {
  timestamped,  // "[date time] [level] message"
  tagged,       // "program: message"
};

// True when stderr is the stream JOURNAL_STREAM names (device:inode), i.e.
// connected to journald, not merely started by a journald-connected shell.
bool stderr_is_journal();

// The syslog priority of a spdlog level: critical 2, error 3, warn 4, info 6,
// debug and trace 7.
int syslog_priority(spdlog::level::level_enum level);

// "<N>message" for the journal, else as style says (program: tagged's tag).
std::unique_ptr<spdlog::formatter> log_formatter(bool to_journal,
                                                 LogStyle style = LogStyle::timestamped,
                                                 const std::string& program = {});

// Makes spdlog's default logger, named program, write to stderr at `level`
// (spdlog's names: trace, debug, info, warn, error, critical, off), flushing every line, in the
// journal's format when `to_journal`. Any thread may log: a line is written whole.
void set_up_logging(const std::string& program, const std::string& level, bool to_journal,
                    LogStyle style = LogStyle::timestamped);

}  // namespace agnocast_service
