#include "agnocast/message_render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "runtime.hpp"

namespace render_test {

struct Cell {
  std::int16_t row;
  agnocast::string note;
};

struct Grid {
  bool valid;
  double scale;
  Cell origin;
  agnocast::vector<Cell> cells;
  std::array<std::uint8_t, 3> rgb;
  agnocast::vector<float> weights;
};

}  // namespace render_test

AGNOCAST_MESSAGE(render_test::Cell, "render_test/msg/Cell", row, note);
AGNOCAST_MESSAGE(render_test::Grid, "render_test/msg/Grid", valid, scale, origin, cells, rgb,
                 weights);

namespace agnocast {
namespace {

using render_test::Grid;

class MessageRender : public ::testing::Test {
 protected:
  static constexpr std::size_t pool_size = 1 << 20;
  void SetUp() override {
    // Left to the leaked test runtime, like every test pool.
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    detail::Runtime::install_for_testing(region, pool_size);
    grid_.valid = true;
    grid_.scale = 0.25;
    grid_.origin = {-3, "a \"quoted\"\nline"};
    grid_.cells.push_back({1, "one"});
    grid_.cells.push_back({2, "a note longer than any small-string buffer"});
    grid_.rgb = {255, 0, 7};
    grid_.weights = {1.5F, std::numeric_limits<float>::quiet_NaN()};
  }
  Grid grid_;
  const Schema schema_ = parse_schema(schema_of<Grid>());
};

TEST_F(MessageRender, TextIsYamlLike) {
  EXPECT_EQ(render_message_text(&grid_, schema_),
            "valid: true\n"
            "scale: 0.25\n"
            "origin:\n"
            "  row: -3\n"
            "  note: \"a \\\"quoted\\\"\\nline\"\n"
            "cells:\n"
            "  - row: 1\n"
            "    note: \"one\"\n"
            "  - row: 2\n"
            "    note: \"a note longer than any small-string buffer\"\n"
            "rgb: [255, 0, 7]\n"
            "weights: [1.5, .nan]\n");
}

TEST_F(MessageRender, JsonIsOneLine) {
  EXPECT_EQ(render_message_json(&grid_, schema_),
            R"({"valid":true,"scale":0.25,"origin":{"row":-3,"note":"a \"quoted\"\nline"},)"
            R"("cells":[{"row":1,"note":"one"},{"row":2,"note":"a note longer than any )"
            R"(small-string buffer"}],"rgb":[255,0,7],"weights":[1.5,null]})");
}

TEST_F(MessageRender, WithoutArraysShowsLengths) {
  const RenderOptions lengths_only{.show_arrays = false};
  EXPECT_EQ(render_message_json(&grid_, schema_, lengths_only),
            R"({"valid":true,"scale":0.25,"origin":{"row":-3,"note":"a \"quoted\"\nline"},)"
            R"("cells":{"length":2},"rgb":{"length":3},"weights":{"length":2}})");
  EXPECT_NE(render_message_text(&grid_, schema_, lengths_only).find("cells: <2 elements>\n"),
            std::string::npos);
}

TEST_F(MessageRender, FollowsOnlyPointersTheCallerCanRead) {
  // Only the Grid itself is "mapped": every string and sequence lies elsewhere.
  const RenderOptions inside_grid{.readable = [this](const void* address, std::size_t bytes) {
    const auto* begin = reinterpret_cast<const std::byte*>(&grid_);
    const auto* at = static_cast<const std::byte*>(address);
    return at >= begin && at + bytes <= begin + sizeof(grid_);
  }};
  grid_.origin.note = "short";  // kept inside the string object (small-string buffer)
  EXPECT_EQ(render_message_json(&grid_, schema_, inside_grid),
            R"({"valid":true,"scale":0.25,"origin":{"row":-3,"note":"short"},)"
            R"("cells":null,"rgb":[255,0,7],"weights":null})");
  EXPECT_NE(render_message_text(&grid_, schema_, inside_grid).find("cells: <unreadable>\n"),
            std::string::npos);
}

TEST_F(MessageRender, EmptySequenceAndRawType) {
  grid_.cells.clear();
  EXPECT_NE(render_message_text(&grid_, schema_).find("cells: []\n"), std::string::npos);
  const std::uint32_t raw = 0x01020304;
  const Schema raw_schema = parse_schema(schema_of<std::uint32_t>());
  EXPECT_EQ(render_message_text(&raw, raw_schema), "bytes: \"04030201\"\n");
  EXPECT_EQ(render_message_json(&raw, raw_schema), R"({"bytes":"04030201"})");
}

}  // namespace
}  // namespace agnocast
