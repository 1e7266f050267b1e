// agnocastd's log: stderr, which systemd hands to journald. There each line
// starts with its syslog priority ("<3>" for an error), which journald strips
// and records, so `journalctl -p err` finds the errors; elsewhere each line
// carries a timestamp and the level's name.
#pragma once

#include <spdlog/formatter.h>

#include <memory>
#include <string>

namespace agnocastd {

// True when stderr is the stream JOURNAL_STREAM names (device:inode), i.e.
// connected to journald, not merely started by a journald-connected shell.
bool stderr_is_journal();

// The syslog priority of a spdlog level: critical 2, error 3, warn 4, info 6,
// debug and trace 7.
int syslog_priority(spdlog::level::level_enum level);

// "<N>message" for the journal, "[date time] [level] message" elsewhere.
std::unique_ptr<spdlog::formatter> log_formatter(bool to_journal);

// Makes the default logger write to stderr at `level`, in the journal's
// format when `to_journal`.
void set_up_logging(const std::string& level, bool to_journal);

}  // namespace agnocastd
