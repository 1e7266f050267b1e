#include "bench_support.hpp"

#include <gtest/gtest.h>

namespace agnocast::bench {
namespace {

TEST(BenchSupport, PayloadPatternDetectsAnyChangedByteAndTheWrongMessage) {
  for (std::size_t size : {0u, 1u, 7u, 8u, 13u, 4096u}) {
    std::vector<std::uint8_t> payload(size);
    fill_payload(payload, 42);
    EXPECT_TRUE(payload_intact(payload, 42)) << size;
    if (size == 0) continue;
    EXPECT_FALSE(payload_intact(payload, 43)) << size;
    payload[size - 1] ^= 1;
    EXPECT_FALSE(payload_intact(payload, 42)) << size;
  }
}

TEST(BenchSupport, SizesParseAndFormatInBinaryUnits) {
  EXPECT_EQ(parse_size("64"), 64u);
  EXPECT_EQ(parse_size("4K"), 4096u);
  EXPECT_EQ(parse_size("64MiB"), std::size_t{64} << 20);
  EXPECT_THROW(parse_size("3X"), std::invalid_argument);
  EXPECT_EQ(format_size(64), "64 B");
  EXPECT_EQ(format_size(4096), "4 KiB");
  EXPECT_EQ(format_size(std::size_t{16} << 20), "16 MiB");
}

TEST(BenchSupport, SharedScratchIsWritableSharedMemoryOfTheAskedSize) {
  SharedScratch scratch(1 << 20);
  ASSERT_EQ(scratch.bytes().size(), std::size_t{1} << 20);
  fill_payload(scratch.bytes(), 7);
  EXPECT_TRUE(payload_intact(scratch.bytes(), 7));
  EXPECT_TRUE(SharedScratch(0).bytes().empty());
}

}  // namespace
}  // namespace agnocast::bench
