#include "agnocast/message_render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <span>
#include <stdexcept>

#include "kernel/fake_kernel.hpp"
#include "kernel/runtime.hpp"

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
    region_ = new (std::align_val_t{4096}) std::byte[pool_size];
    detail::Runtime::install_for_testing(region_, pool_size,
                                         std::make_unique<detail::FakeKernel>());
    grid_.valid = true;
    grid_.scale = 0.25;
    grid_.origin = {-3, "a \"quoted\"\nline"};
    grid_.cells.push_back({1, "one"});
    grid_.cells.push_back({2, "a note longer than any small-string buffer"});
    grid_.rgb = {255, 0, 7};
    grid_.weights = {1.5F, std::numeric_limits<float>::quiet_NaN()};
  }
  std::byte* region_ = nullptr;
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

TEST_F(MessageRender, EmptySequenceAndRawType) {
  grid_.cells.clear();
  EXPECT_NE(render_message_text(&grid_, schema_).find("cells: []\n"), std::string::npos);
  const std::uint32_t raw = 0x01020304;
  const Schema raw_schema = parse_schema(schema_of<std::uint32_t>());
  EXPECT_EQ(render_message_text(&raw, raw_schema), "bytes: \"04030201\"\n");
  EXPECT_EQ(render_message_json(&raw, raw_schema), R"({"bytes":"04030201"})");
}

// A publisher's message as a reader in another process sees it: in the
// publisher's pool (small strings included), never destroyed, poked at will.
class HostileMessage : public MessageRender {
 protected:
  void SetUp() override {
    MessageRender::SetUp();
    auto& runtime = *detail::Runtime::current();
    void* memory = runtime.allocate(sizeof(Grid), alignof(Grid));
    message_ = reinterpret_cast<std::byte*>(new (memory) Grid(grid_));
    checked_.readable = std::span<const std::byte>(region_, pool_size);
  }

  const SchemaField& field(std::string_view name) const {
    for (const SchemaField& f : schema_.types[0].fields) {
      if (f.name == name) return f;
    }
    throw std::logic_error("no field " + std::string(name));
  }
  template <class T>
  T peek(std::size_t offset) const {
    T value;
    std::memcpy(&value, message_ + offset, sizeof(T));
    return value;
  }
  template <class T>
  void poke(std::size_t offset, T value) {
    std::memcpy(message_ + offset, &value, sizeof(T));
  }
  std::size_t vector_begin(std::string_view name) const {
    return field(name).offset + schema_.containers.vector_begin_offset;
  }
  std::size_t vector_end(std::string_view name) const {
    return field(name).offset + schema_.containers.vector_end_offset;
  }
  // The string of field `origin`'s `note`.
  std::size_t note_data() const {
    return field("origin").offset + schema_.types[1].fields[1].offset +
           schema_.containers.string_data_offset;
  }
  std::size_t note_length() const {
    return field("origin").offset + schema_.types[1].fields[1].offset +
           schema_.containers.string_length_offset;
  }
  std::string text() const { return render_message_text(message_, schema_, checked_); }
  std::string json() const { return render_message_json(message_, schema_, checked_); }

  std::byte* message_ = nullptr;
  RenderOptions checked_;
};

TEST_F(HostileMessage, AnIntactMessageRendersAsUnchecked) {
  ASSERT_EQ(schema_.types[1].name, "render_test/msg/Cell");
  EXPECT_EQ(text(), render_message_text(&grid_, schema_));
  EXPECT_EQ(json(), render_message_json(&grid_, schema_));
}

TEST_F(HostileMessage, SequenceOutsideThePoolIsAMarker) {
  const std::uintptr_t outside = reinterpret_cast<std::uintptr_t>(region_) + pool_size;
  poke<std::uintptr_t>(vector_begin("weights"), outside);
  poke<std::uintptr_t>(vector_end("weights"), outside + 2 * sizeof(float));
  EXPECT_NE(text().find("weights: <invalid: sequence outside the publisher's pool>\n"),
            std::string::npos);
  EXPECT_NE(json().find(R"("weights":{"invalid":"sequence outside the publisher's pool"}})"),
            std::string::npos);
  poke<std::uintptr_t>(vector_begin("cells"), 16);  // a null-page address
  poke<std::uintptr_t>(vector_end("cells"), 16 + sizeof(render_test::Cell));
  EXPECT_NE(text().find("cells: <invalid: sequence outside the publisher's pool>\n"),
            std::string::npos);
}

TEST_F(HostileMessage, SequenceRunningPastThePoolEndIsAMarker) {
  const auto begin = peek<std::uintptr_t>(vector_begin("weights"));
  poke<std::uintptr_t>(vector_end("weights"), begin + (std::uintptr_t{1} << 40));
  EXPECT_NE(text().find("weights: <invalid: sequence outside the publisher's pool>\n"),
            std::string::npos);
}

TEST_F(HostileMessage, ImpossibleSequenceLengthsAreMarkers) {
  const auto begin = peek<std::uintptr_t>(vector_begin("weights"));
  poke<std::uintptr_t>(vector_end("weights"), begin - sizeof(float));
  EXPECT_NE(text().find("weights: <invalid: sequence ends before its begin>\n"), std::string::npos);
  poke<std::uintptr_t>(vector_end("weights"), begin + 3);
  EXPECT_NE(text().find("weights: <invalid: sequence length is no whole number of elements>\n"),
            std::string::npos);
}

TEST_F(HostileMessage, MisalignedSequenceIsAMarker) {
  const auto begin = peek<std::uintptr_t>(vector_begin("weights"));
  poke<std::uintptr_t>(vector_begin("weights"), begin + 1);
  poke<std::uintptr_t>(vector_end("weights"), begin + 1 + sizeof(float));
  EXPECT_NE(json().find(R"("weights":{"invalid":"misaligned sequence"})"), std::string::npos);
}

TEST_F(HostileMessage, StringsOutsideThePoolOrHugeAreMarkers) {
  poke<std::size_t>(note_length(), std::size_t{1} << 40);
  EXPECT_NE(text().find("  note: <invalid: string outside the publisher's pool>\n"),
            std::string::npos);
  poke<std::size_t>(note_length(), 4);
  poke<std::uintptr_t>(note_data(), 8);
  EXPECT_NE(json().find(R"("note":{"invalid":"string outside the publisher's pool"})"),
            std::string::npos);
  // The other fields still render.
  EXPECT_NE(json().find(R"("rgb":[255,0,7])"), std::string::npos);
}

TEST_F(HostileMessage, AMessageOutsideThePoolIsAMarker) {
  const Grid elsewhere = grid_;  // on the stack, not in the pool
  EXPECT_EQ(render_message_text(&elsewhere, schema_, checked_),
            "<invalid: message outside the publisher's pool>\n");
  EXPECT_EQ(render_message_json(&elsewhere, schema_, checked_),
            R"({"invalid":"message outside the publisher's pool"})");
  EXPECT_EQ(render_message_json(message_ + 1, schema_, checked_),
            R"({"invalid":"misaligned message"})");
}

TEST_F(HostileMessage, ValuesBeyondTheBudgetAreMarkers) {
  // Containers that alias one another would cost as much: the budget bounds both.
  checked_.max_values = 8;
  const std::string rendered = text();
  EXPECT_NE(rendered.find("rgb: [255, 0, 7]\n"), std::string::npos);
  EXPECT_NE(rendered.find("<invalid: too many values to show>"), std::string::npos);
  checked_.show_arrays = false;  // lengths cost nothing, only the 15 bytes of origin.note
  checked_.max_values = 15;
  EXPECT_EQ(text().find("invalid"), std::string::npos);
  checked_.max_values = 14;
  EXPECT_NE(text().find("  note: <invalid: too many values to show>\n"), std::string::npos);
}

}  // namespace
}  // namespace agnocast
