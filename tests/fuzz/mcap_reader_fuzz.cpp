// The MCAP reader over any bytes: opening, the summary and a full scan with
// CRCs checked must end in a FormatError or a result, within the fuzzer's
// memory limit (declared lengths, chunk sizes and compressed sizes lie). Its
// chunks may hold 16 MiB of records, not the default 1 GiB: the same code
// refuses them, and a bomb decompressed up to the limit stays fast and
// under the fuzzer's 512 MiB per allocation.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <system_error>

#include "agnocast/mcap/reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int fd = ::memfd_create("mcap", MFD_CLOEXEC);
  if (fd < 0) return 0;
  if (size > 0 && ::write(fd, data, size) != static_cast<ssize_t>(size)) {
    ::close(fd);
    return 0;
  }
  try {
    const agnocast::mcap::Reader reader("/proc/self/fd/" + std::to_string(fd),
                                        {.chunk_records_max = std::uint64_t{16} << 20});
    std::size_t seen = 0;
    agnocast::mcap::Visitor visitor;
    visitor.schema = [&](const agnocast::mcap::Schema& schema) { seen += schema.data.size(); };
    visitor.channel = [&](const agnocast::mcap::Channel& channel) { seen += channel.topic.size(); };
    visitor.message = [&](const agnocast::mcap::MessageView& message) {
      seen += message.data.size();
    };
    reader.scan(visitor);
    reader.scan(visitor, false);
  } catch (const agnocast::mcap::FormatError&) {
  } catch (const std::system_error&) {
  }
  ::close(fd);
  return 0;
}
