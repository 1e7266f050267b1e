// Files that readers must never see half written (status files, state):
// the text goes to "<path>.tmp", is flushed to disk (fsync), then renamed
// over path, so a reader finds the old file or the new one, whole.
//
//   agnocast_service::write_file_atomically("/run/agnocast/x.json", json.dump() + "\n");
#pragma once

#include <sys/types.h>

#include <string>

namespace agnocast_service {

// Replaces path with text, with exactly `mode` whatever the umask, creating
// its folder (0755) when missing. Throws std::system_error (the temporary
// file is removed then).
void write_file_atomically(const std::string& path, const std::string& text, mode_t mode = 0644);

// Creates path's parent folder, and those above it, mode 0755 whatever the
// umask; nothing when it exists. Throws std::filesystem::filesystem_error.
void create_parent_directory(const std::string& path);

}  // namespace agnocast_service
