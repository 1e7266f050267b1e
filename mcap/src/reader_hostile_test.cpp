// Files made to hurt the reader: lengths of 2^63, a chunk inside a chunk, a
// zstd bomb, lz4 chunks whose sizes lie. Each is refused with a reason, and
// the reader's allocations stay within a stated bound while it reads them.
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>

#include "agnocast/mcap/reader.hpp"
#include "agnocast/mcap/writer.hpp"

// Every operator new of this test binary is counted, so that a test can say
// how much the reader held at once. The codecs' own contexts (malloc in
// libzstd and liblz4) are not counted: the codecs bound them (a zstd window
// of at most 128 MiB, lz4 blocks of at most 4 MiB).
namespace {
std::atomic<std::size_t> live_bytes{0};
std::atomic<std::size_t> peak_bytes{0};
}  // namespace

void* operator new(std::size_t size) {
  void* block = std::malloc(size == 0 ? 1 : size);
  if (block == nullptr) throw std::bad_alloc();
  const std::size_t now = live_bytes += malloc_usable_size(block);
  std::size_t peak = peak_bytes.load();
  while (now > peak && !peak_bytes.compare_exchange_weak(peak, now)) {
  }
  return block;
}
void operator delete(void* block) noexcept {
  if (block == nullptr) return;
  live_bytes -= malloc_usable_size(block);
  std::free(block);
}
void operator delete(void* block, std::size_t) noexcept { operator delete(block); }

namespace agnocast::mcap {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint64_t KiB = 1024;
constexpr std::uint64_t MiB = 1024 * KiB;
constexpr std::uint64_t GiB = 1024 * MiB;
// Where the first data record starts: the magic (8 bytes), then the Header below (28).
constexpr std::size_t first_record_at = 36;

// A record with the length it declares, whatever its content's real length.
Bytes raw_record(Opcode opcode, std::uint64_t declared_length, const Bytes& content) {
  Bytes out(record_prefix_size + content.size());
  out[0] = static_cast<std::uint8_t>(opcode);
  std::memcpy(out.data() + 1, &declared_length, sizeof declared_length);
  std::copy(content.begin(), content.end(), out.begin() + record_prefix_size);
  return out;
}

// A Chunk record holding `stored` as its records, declaring `uncompressed_size`.
Bytes chunk_record(std::string compression, const Bytes& stored, std::uint64_t uncompressed_size) {
  Bytes out;
  write_record(out, Chunk{.message_start_time = 1,
                          .message_end_time = 2,
                          .uncompressed_size = uncompressed_size,
                          .uncompressed_crc = 0,
                          .compression = std::move(compression),
                          .records = stored});
  return out;
}

Bytes channel_and_message() {
  Bytes out;
  write_record(out, Channel{1, 0, "/hostile", "cdr", {}});
  write_record(out, Message{1, 0, 10, 10, {1, 2, 3}});
  return out;
}

// zeros_size zero bytes through libzstd's streaming API, a megabyte at a
// time, the frame declaring their size: 4 GiB make about 128 KiB.
Bytes zstd_zeros(std::uint64_t zeros_size) {
  const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(),
                                                                     &ZSTD_freeCCtx);
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, 1);
  ZSTD_CCtx_setPledgedSrcSize(context.get(), zeros_size);
  const Bytes zeros(MiB, 0);
  Bytes frame;
  Bytes piece(ZSTD_CStreamOutSize());
  for (std::uint64_t done = 0; done < zeros_size;) {
    const std::size_t size =
        static_cast<std::size_t>(std::min<std::uint64_t>(MiB, zeros_size - done));
    done += size;
    const ZSTD_EndDirective directive = done == zeros_size ? ZSTD_e_end : ZSTD_e_continue;
    ZSTD_inBuffer in{zeros.data(), size, 0};
    for (;;) {
      ZSTD_outBuffer out{piece.data(), piece.size(), 0};
      const std::size_t left = ZSTD_compressStream2(context.get(), &out, &in, directive);
      EXPECT_FALSE(ZSTD_isError(left)) << ZSTD_getErrorName(left);
      frame.insert(frame.end(), piece.begin(), piece.begin() + static_cast<long>(out.pos));
      if (directive == ZSTD_e_end ? left == 0 : in.pos == in.size) break;
    }
  }
  return frame;
}

// An lz4 frame of `data` whose header does not say its size (compress()'s
// does): the reader alone then sees a chunk's size lie.
Bytes lz4_frame_without_size(const Bytes& data) {
  const LZ4F_preferences_t preferences{};
  Bytes frame(LZ4F_compressFrameBound(data.size(), &preferences));
  const std::size_t size =
      LZ4F_compressFrame(frame.data(), frame.size(), data.data(), data.size(), &preferences);
  EXPECT_FALSE(LZ4F_isError(size)) << LZ4F_getErrorName(size);
  frame.resize(size);
  return frame;
}

class HostileMcap : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() /
            ("agnocast-mcap-hostile-" + std::to_string(::getpid()) + ".mcap");
  }
  void TearDown() override { fs::remove(path_); }

  // magic, Header, the data records, DataEnd; then, when summary is given, those
  // records as the summary, a Footer pointing at them (or at summary_start) and the magic.
  void write(const Bytes& data, const std::optional<Bytes>& summary = std::nullopt,
             std::optional<std::uint64_t> summary_start = std::nullopt) {
    Bytes file(magic.begin(), magic.end());
    write_record(file, Header{"ros2", "hostile"});
    file.insert(file.end(), data.begin(), data.end());
    write_record(file, DataEnd{0});
    if (summary) {
      const std::uint64_t start = file.size();
      file.insert(file.end(), summary->begin(), summary->end());
      write_record(file, Footer{summary_start.value_or(start), 0, 0});
      file.insert(file.end(), magic.begin(), magic.end());
    }
    std::ofstream(path_, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(file.data()), static_cast<long>(file.size()));
  }

  // Opens and scans the file, noting the most bytes the reader held at once.
  ScanResult scan(ReaderOptions options = {}) {
    messages_ = 0;
    const std::size_t before = live_bytes;
    peak_bytes = before;
    ScanResult result;
    {
      const Reader reader(path_.string(), options);
      summary_problem_ = reader.summary_problem();
      // Every callback set, so that every record is parsed.
      Visitor visitor;
      visitor.schema = [](const Schema&) {};
      visitor.channel = [](const Channel&) {};
      visitor.message = [&](const MessageView&) { ++messages_; };
      visitor.metadata = [](const Metadata&) {};
      visitor.chunk = [](const Chunk&) {};
      result = reader.scan(visitor);
    }
    peak_ = peak_bytes - before;
    return result;
  }

  fs::path path_;
  std::string summary_problem_;
  std::size_t messages_ = 0;
  std::size_t peak_ = 0;
};

TEST_F(HostileMcap, RecordLengthsOf2To63AndOtherHugeValuesStopTheScan) {
  const Bytes content(30, 0);
  for (const std::uint64_t length :
       {std::uint64_t{1} << 63, (std::uint64_t{1} << 63) - 1, ~std::uint64_t{0},
        std::uint64_t{1} << 32, std::uint64_t{31} + record_prefix_size + 8}) {
    SCOPED_TRACE(length);
    write(raw_record(Opcode::Message, length, content));
    const ScanResult result = scan();
    EXPECT_FALSE(result.reached_data_end);
    EXPECT_NE(result.stopped.find("cut short inside a record (Message (0x05), " +
                                  std::to_string(length) + " bytes)"),
              std::string::npos)
        << result.stopped;
    EXPECT_LT(peak_, 64 * KiB);
    // The same inside a chunk.
    write(chunk_record("", raw_record(Opcode::Message, length, content), 9 + 30));
    const ScanResult in_chunk = scan();
    EXPECT_NE(in_chunk.stopped.find("a chunk's records are cut short inside a record"),
              std::string::npos)
        << in_chunk.stopped;
    EXPECT_LT(peak_, 64 * KiB);
  }
}

TEST_F(HostileMcap, FieldLengthsOf2To63AndOtherHugeValuesStopTheScan) {
  // A chunk whose records field declares 2^63 bytes.
  Bytes chunk = chunk_record("", channel_and_message(), channel_and_message().size());
  const std::size_t records_length_at = record_prefix_size + 8 + 8 + 8 + 4 + 4;
  std::uint64_t huge = std::uint64_t{1} << 63;
  std::memcpy(chunk.data() + records_length_at, &huge, sizeof huge);
  write(chunk);
  ScanResult result = scan();
  EXPECT_NE(result.stopped.find("Chunk record ends inside a field"), std::string::npos)
      << result.stopped;
  EXPECT_LT(peak_, 64 * KiB);

  // A Schema whose name declares 2^32 - 1 bytes, inside a chunk.
  Bytes schema;
  write_record(schema, Schema{1, "x", "ros2msg", {}});
  const std::uint32_t longest = ~std::uint32_t{0};
  std::memcpy(schema.data() + record_prefix_size + 2, &longest, sizeof longest);
  write(chunk_record("", schema, schema.size()));
  result = scan();
  EXPECT_NE(result.stopped.find("Schema record ends inside a field"), std::string::npos)
      << result.stopped;
  EXPECT_LT(peak_, 64 * KiB);

  // A summary at byte 2^63, and a summary record of 2^63 bytes.
  write({}, Bytes{}, huge);
  scan();
  EXPECT_EQ(summary_problem_, "the footer's summary offset lies outside the file");
  write({}, raw_record(Opcode::Statistics, huge, Bytes(8, 0)));
  scan();
  EXPECT_EQ(summary_problem_.rfind("summary cut short inside a record (Statistics (0x0b), ", 0), 0u)
      << summary_problem_;
  EXPECT_LT(peak_, 64 * KiB);
}

TEST_F(HostileMcap, ChunksDeclaringMoreThanTheLimitAreRefusedBeforeDecompressing) {
  const Bytes records = channel_and_message();
  for (const Compression compression : {Compression::None, Compression::Zstd, Compression::Lz4}) {
    for (const std::uint64_t declared :
         {std::uint64_t{1} << 63, ~std::uint64_t{0}, default_chunk_records_max + 1}) {
      SCOPED_TRACE(std::string(compression_name(compression)) + " " + std::to_string(declared));
      write(chunk_record(std::string(compression_name(compression)), compress(compression, records),
                         declared));
      const ScanResult result = scan();
      EXPECT_EQ(result.stopped, "mcap: a chunk declares " + std::to_string(declared) +
                                    " bytes of records, more than the 1073741824 a chunk may "
                                    "hold (the reader's limit) at byte " +
                                    std::to_string(first_record_at));
      EXPECT_EQ(messages_, 0u);
      EXPECT_LT(peak_, 64 * KiB);
    }
  }
  // At the limit a chunk is read; a byte over, it is not.
  write(chunk_record("", records, records.size()));
  EXPECT_TRUE(scan({.chunk_records_max = records.size()}).reached_data_end);
  EXPECT_EQ(messages_, 1u);
  EXPECT_NE(scan({.chunk_records_max = records.size() - 1}).stopped.find("the reader's limit"),
            std::string::npos);
}

TEST_F(HostileMcap, AChunkInsideAChunkIsRefused) {
  const Bytes inner = chunk_record("", channel_and_message(), channel_and_message().size());
  for (const Compression compression : {Compression::None, Compression::Zstd, Compression::Lz4}) {
    SCOPED_TRACE(compression_name(compression));
    write(chunk_record(std::string(compression_name(compression)), compress(compression, inner),
                       inner.size()));
    const ScanResult result = scan();
    EXPECT_FALSE(result.reached_data_end);
    EXPECT_EQ(result.stopped, "the chunk at byte " + std::to_string(first_record_at) +
                                  " holds a Chunk (0x06) record (at byte 0 of its records): a "
                                  "chunk holds only Schema, Channel and Message records");
    EXPECT_EQ(messages_, 0u);
  }
  // Nor does a chunk hold a DataEnd, a Footer or a Header; records of
  // opcodes the format does not define are skipped, as it asks.
  for (const Opcode opcode : {Opcode::DataEnd, Opcode::Footer, Opcode::Header}) {
    write(chunk_record("", raw_record(opcode, 4, Bytes(4, 0)), 13));
    EXPECT_NE(scan().stopped.find("a chunk holds only"), std::string::npos);
  }
  Bytes unknown = raw_record(static_cast<Opcode>(0x80), 4, Bytes(4, 0));
  const Bytes records = channel_and_message();
  unknown.insert(unknown.end(), records.begin(), records.end());
  write(chunk_record("", unknown, unknown.size()));
  EXPECT_TRUE(scan().reached_data_end);
  EXPECT_EQ(messages_, 1u);
}

// 4 GiB of zeros, compressed to about 128 KiB.
TEST_F(HostileMcap, AZstdBombIsRefusedWithBoundedMemory) {
  const Bytes bomb = zstd_zeros(4 * GiB);
  ASSERT_LT(bomb.size(), 256 * KiB);
  ASSERT_EQ(ZSTD_getFrameContentSize(bomb.data(), bomb.size()), 4 * GiB);
  // Declaring its size: over the limit, refused before a byte is decompressed.
  write(chunk_record("zstd", bomb, 4 * GiB));
  ScanResult result = scan();
  EXPECT_NE(result.stopped.find("declares 4294967296 bytes of records, more than the 1073741824"),
            std::string::npos)
      << result.stopped;
  EXPECT_LT(peak_, bomb.size() + 64 * KiB);  // the chunk as stored

  // Declaring less: decompressed up to the declared size, then refused.
  write(chunk_record("zstd", bomb, MiB));
  result = scan();
  EXPECT_NE(
      result.stopped.find("zstd chunk decompresses to more than the 1048576 bytes it declares"),
      std::string::npos)
      << result.stopped;
  // The records' buffer doubles up to the declared size: 1.5 times it at most.
  EXPECT_LT(peak_, bomb.size() + 3 * MiB / 2 + 64 * KiB);

  // A lower limit: refused at it.
  write(chunk_record("zstd", bomb, 16 * MiB + 1));
  result = scan({.chunk_records_max = 16 * MiB});
  EXPECT_NE(result.stopped.find("more than the 16777216 a chunk may hold"), std::string::npos)
      << result.stopped;
  EXPECT_LT(peak_, bomb.size() + 64 * KiB);
}

TEST_F(HostileMcap, Lz4ChunksWhoseSizesLieAreRefused) {
  const Bytes zeros(MiB, 0);
  const auto stopped_with = [&](std::uint64_t declared, const Bytes& stored) {
    write(chunk_record("lz4", stored, declared));
    const ScanResult result = scan();
    EXPECT_FALSE(result.reached_data_end);
    EXPECT_EQ(messages_, 0u);
    return result.stopped;
  };
  for (const Bytes& frame : {compress(Compression::Lz4, zeros), lz4_frame_without_size(zeros)}) {
    SCOPED_TRACE(frame.size());
    std::string stopped = stopped_with(KiB, frame);
    EXPECT_NE(stopped.find("lz4 chunk decompresses to more than the 1024 bytes"), std::string::npos)
        << stopped;
    EXPECT_LT(peak_, frame.size() + 64 * KiB);
    stopped = stopped_with(2 * MiB, frame);
    EXPECT_NE(stopped.find("lz4 chunk decompresses to 1048576 bytes, not the 2097152 it declares"),
              std::string::npos)
        << stopped;
    // The records' buffer doubled from 1 MiB to 2 MiB: both held for a moment.
    EXPECT_LT(peak_, frame.size() + 3 * MiB + 64 * KiB);
    stopped = stopped_with(std::uint64_t{1} << 63, frame);
    EXPECT_NE(stopped.find("the reader's limit"), std::string::npos) << stopped;
    EXPECT_LT(peak_, frame.size() + 64 * KiB);
  }
}

// What the reader refuses, the writer never writes.
TEST(McapWriter, RefusesAMessageNoChunkCouldHold) {
  const fs::path path =
      fs::temp_directory_path() / ("agnocast-mcap-big-" + std::to_string(::getpid()) + ".mcap");
  // Address space only: the writer refuses before it reads a byte.
  const std::size_t size = message_data_max + 1;
  void* pages =
      ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  ASSERT_NE(pages, MAP_FAILED);
  {
    Writer writer(path.string(), {.profile = "", .compression = Compression::None});
    const auto channel = writer.add_channel(0, "/x", "cdr", {});
    EXPECT_THROW(writer.write_message(channel, 1, 1,
                                      std::span(static_cast<const std::uint8_t*>(pages), size)),
                 FormatError);
    writer.write_message(channel, 2, 2, std::vector<std::uint8_t>{1});
  }
  ::munmap(pages, size);
  const Reader reader(path.string());
  EXPECT_EQ(reader.summary()->statistics->message_count, 1u);
  fs::remove(path);
}

}  // namespace
}  // namespace agnocast::mcap
