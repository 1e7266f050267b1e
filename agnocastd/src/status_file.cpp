#include "status_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <system_error>

#include "errno_error.hpp"

namespace agnocastd {

void write_status_file(const std::string& path, const std::string& text) {
  const std::filesystem::path target(path);
  if (target.has_parent_path() && !std::filesystem::exists(target.parent_path())) {
    std::filesystem::create_directories(target.parent_path());
    ::chmod(target.parent_path().c_str(), 0755);
  }
  const std::string temporary = path + ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_errno("cannot create " + temporary);
  // fchmod: the umask must not make the file unreadable for the CLI.
  const bool written = ::fchmod(fd, 0644) == 0 &&
                       ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const int saved_errno = errno;
  ::close(fd);
  if (!written) {
    ::unlink(temporary.c_str());
    errno = saved_errno;
    throw_errno("cannot write " + temporary);
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) throw_errno("cannot replace " + path);
}

}  // namespace agnocastd
