// bag info on files written here: complete, cut short, and not MCAP at all.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <utility>
#include <vector>

#include "agnocast/mcap/writer.hpp"
#include "bag/bag.hpp"

namespace agnocast::cli {
namespace {

namespace fs = std::filesystem;

class BagInfo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("agnocast-bag-info-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // /fast: 101 messages over 1 s; /slow: 11. Chunks of 1 KiB, lz4.
  std::string write_file() {
    const std::string path = (dir_ / "two.mcap").string();
    mcap::Writer writer(
        path, {.profile = "ros2", .compression = mcap::Compression::Lz4, .chunk_size = 1024});
    const auto schema = writer.add_schema("std_msgs/msg/Header", "ros2msg", {'x'});
    const auto fast = writer.add_channel(schema, "/fast", "cdr", {});
    const auto slow = writer.add_channel(schema, "/slow", "cdr", {});
    const std::uint64_t t0 = 1'700'000'000'000'000'000;
    for (std::uint64_t i = 0; i <= 100; ++i) {
      const std::vector<std::uint8_t> data(64, static_cast<std::uint8_t>(i));
      writer.write_message(fast, t0 + i * 10'000'000, t0, data);
      if (i % 10 == 0) writer.write_message(slow, t0 + i * 10'000'000, t0, data);
    }
    writer.close();
    return path;
  }

  fs::path dir_;
};

TEST_F(BagInfo, ACompleteFileFromItsSummary) {
  const std::string path = write_file();
  const nlohmann::json info = bag_info_json(path);
  EXPECT_EQ(info["path"], path);
  EXPECT_EQ(info["size_bytes"], fs::file_size(path));
  EXPECT_EQ(info["complete"], true);
  EXPECT_EQ(info["compression"], "lz4");
  EXPECT_EQ(info["messages"], 112);
  EXPECT_EQ(info["start_ns"], 1'700'000'000'000'000'000u);
  EXPECT_EQ(info["end_ns"], 1'700'000'001'000'000'000u);
  EXPECT_DOUBLE_EQ(info["duration_s"].get<double>(), 1.0);
  ASSERT_EQ(info["topics"].size(), 2u);
  EXPECT_EQ(info["topics"][0]["name"], "/fast");
  EXPECT_EQ(info["topics"][0]["type"], "std_msgs/msg/Header");
  EXPECT_EQ(info["topics"][0]["encoding"], "cdr");
  EXPECT_EQ(info["topics"][0]["messages"], 101);
  EXPECT_DOUBLE_EQ(info["topics"][0]["rate_hz"].get<double>(), 101.0);
  EXPECT_EQ(info["topics"][1]["messages"], 11);
  const std::string table = bag_info_table(info);
  EXPECT_NE(table.find("/slow"), std::string::npos);
  EXPECT_EQ(table.find("Incomplete"), std::string::npos);
}

TEST_F(BagInfo, ACutFileIsIncompleteAndCountsItsWholeChunks) {
  const std::string path = write_file();
  const auto size = fs::file_size(path);
  fs::resize_file(path, size * 2 / 3);
  const nlohmann::json info = bag_info_json(path);
  EXPECT_EQ(info["complete"], false);
  EXPECT_FALSE(info["incomplete_reason"].get<std::string>().empty());
  const auto messages = info["messages"].get<std::uint64_t>();
  EXPECT_GT(messages, 20u);
  EXPECT_LT(messages, 112u);
  EXPECT_EQ(info["topics"][0]["name"], "/fast");
  EXPECT_EQ(info["topics"][0]["type"], "std_msgs/msg/Header");
  EXPECT_NE(bag_info_table(info).find("Incomplete"), std::string::npos);
}

TEST_F(BagInfo, WhatIsNotMcapIsAnInputErrorNamingTheFile) {
  const std::string text = (dir_ / "notes.txt").string();
  std::ofstream(text) << "not a bag\n";
  try {
    bag_info_json(text);
    ADD_FAILURE() << "a text file was read as MCAP";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(text), std::string::npos);
  }
  const std::string missing = (dir_ / "missing.mcap").string();
  try {
    bag_info_json(missing);
    ADD_FAILURE() << "a missing file was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(missing), std::string::npos);
  }
}

// Hostile files: huge or short lengths, a chunk's size lie, a wrong opcode,
// a bad CRC. bag info names the file in its error (exit 2) or says the file
// is incomplete and why; it never crashes or allocates a declared size.
TEST_F(BagInfo, HostileFilesAreAnErrorNamingTheFileOrIncomplete) {
  const std::string original = write_file();
  const std::string path = (dir_ / "hostile.mcap").string();
  auto patch = [&](std::uint64_t offset, const auto value) {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(static_cast<std::streamoff>(offset));
    file.write(reinterpret_cast<const char*>(&value), sizeof value);
  };
  const std::uint64_t size = fs::file_size(original);
  // The magic (8) and the Header record come first; the first chunk follows.
  std::uint64_t first_chunk = 0;
  {
    std::ifstream in(original, std::ios::binary);
    in.seekg(9);
    std::uint64_t header_length = 0;
    in.read(reinterpret_cast<char*>(&header_length), sizeof header_length);
    first_chunk = 8 + 9 + header_length;
  }
  const std::vector<std::pair<const char*, std::function<void()>>> cases{
      {"the Header's length past the end", [&] { patch(9, std::uint64_t{1} << 62); }},
      {"a chunk's length of 2^63", [&] { patch(first_chunk + 1, std::uint64_t{1} << 63); }},
      {"a chunk declaring 2^60 bytes",
       [&] { patch(first_chunk + 9 + 16, std::uint64_t{1} << 60); }},
      {"a chunk's CRC wrong", [&] { patch(first_chunk + 9 + 24, std::uint32_t{0xDEADBEEF}); }},
      {"a wrong opcode", [&] { patch(first_chunk, std::uint8_t{0x7F}); }},
      {"the summary's CRC wrong", [&] { patch(size - 8 - 4, std::uint32_t{0xDEADBEEF}); }},
      {"a summary offset past the end", [&] { patch(size - 8 - 20, ~std::uint64_t{0} >> 1); }},
  };
  for (const auto& [what, damage] : cases) {
    SCOPED_TRACE(what);
    fs::copy_file(original, path, fs::copy_options::overwrite_existing);
    damage();
    try {
      const nlohmann::json info = bag_info_json(path);
      if (info["complete"] == false) {
        EXPECT_FALSE(info["incomplete_reason"].get<std::string>().empty());
      } else {
        EXPECT_EQ(info["messages"], 112) << "a complete summary is the file's";
      }
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
  }
}

TEST(BagRecordHelpers, OutputPath) {
  const fs::path dir =
      fs::temp_directory_path() / ("agnocast-bag-out-" + std::to_string(::getpid()));
  EXPECT_EQ(bag_output_path("run.mcap", 0), "run.mcap");
  const std::string inside = bag_output_path(dir.string() + "/", 0);
  EXPECT_TRUE(fs::is_directory(dir));
  EXPECT_EQ(fs::path(inside).parent_path(), dir);
  EXPECT_EQ(fs::path(inside).extension(), ".mcap");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace agnocast::cli
