#include "agnocast/json_to_cdr.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <new>
#include <string>

#include "agnocast/message_render.hpp"
#include "agnocast/schema_cdr.hpp"
#include "kernel/fake_kernel.hpp"
#include "kernel/runtime.hpp"
#include "schema/cdr_to_pool.hpp"

namespace json_cdr_test {

struct Cell {
  std::int16_t row;
  agnocast::string note;
};

// Every kind of field, in every shape the schema model has.
struct Every {
  bool flag;
  std::int8_t i8;
  std::uint8_t u8;
  std::int16_t i16;
  std::uint16_t u16;
  std::int32_t i32;
  std::uint32_t u32;
  std::int64_t i64;
  std::uint64_t u64;
  float f32;
  double f64;
  agnocast::string text;
  Cell cell;
  std::array<std::int32_t, 3> triple;
  std::array<Cell, 2> pair;
  std::array<agnocast::string, 2> names;
  agnocast::vector<double> weights;
  agnocast::vector<Cell> cells;
  agnocast::vector<agnocast::string> labels;
  agnocast::vector<std::uint8_t> bytes;
};

struct Point {
  double x;
  double y;
};

// A field of bytes without a description: it has no CDR form.
struct WithOpaque {
  std::int32_t id;
  Point raw;
};

}  // namespace json_cdr_test

AGNOCAST_MESSAGE(json_cdr_test::Cell, "json_cdr_test/msg/Cell", row, note);
AGNOCAST_MESSAGE(json_cdr_test::Every, "json_cdr_test/msg/Every", flag, i8, u8, i16, u16, i32, u32,
                 i64, u64, f32, f64, text, cell, triple, pair, names, weights, cells, labels,
                 bytes);
AGNOCAST_MESSAGE(json_cdr_test::WithOpaque, "json_cdr_test/msg/WithOpaque", id, raw);

namespace agnocast {
namespace {

using json_cdr_test::Every;

class JsonToCdr : public ::testing::Test {
 protected:
  static constexpr std::size_t pool_size = 1 << 20;
  void SetUp() override {
    // Left to the leaked test runtime, like every test pool.
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    detail::Runtime::install_for_testing(region, pool_size, std::make_unique<detail::FakeKernel>());
  }

  // What the generated-type-free writer makes of a message built in C++.
  std::vector<std::uint8_t> cdr_of(const Every& message) const {
    std::vector<std::uint8_t> out;
    serialize_with_schema(&message, schema_, out);
    return out;
  }

  // The error's text, or "" when the JSON is accepted.
  std::string refusal(const std::string& json) const { return refusal(json, schema_); }
  static std::string refusal(const std::string& json, const Schema& schema,
                             const JsonToCdrOptions& options = {}) {
    try {
      json_to_cdr(json, schema, options);
    } catch (const JsonInputError& error) {
      return error.what();
    }
    return "";
  }

  Schema schema_ = parse_schema(schema_of<Every>());
};

TEST_F(JsonToCdr, EveryFieldKindAndShapeIsWhatTheSchemaWriterWrites) {
  Every message{};
  message.flag = true;
  message.i8 = -128;
  message.u8 = 255;
  message.i16 = -32768;
  message.u16 = 65535;
  message.i32 = std::numeric_limits<std::int32_t>::min();
  message.u32 = std::numeric_limits<std::uint32_t>::max();
  message.i64 = std::numeric_limits<std::int64_t>::min();
  message.u64 = std::numeric_limits<std::uint64_t>::max();
  message.f32 = 0.1F;
  message.f64 = -2.5e300;
  message.text = "grüße \"quoted\"\n";
  message.cell = {7, "a note longer than any small-string buffer"};
  message.triple = {1, -2, 3};
  message.pair[0] = {1, "one"};
  message.pair[1] = {2, "two"};
  message.names = {"left", "right"};
  message.weights = {0.5, 1.25};
  message.cells.push_back({3, "three"});
  message.labels.push_back("a");
  message.labels.push_back("");
  message.bytes = {0, 1, 255};
  const std::string json = R"({
    "flag": true, "i8": -128, "u8": 255, "i16": -32768, "u16": 65535,
    "i32": -2147483648, "u32": 4294967295,
    "i64": -9223372036854775808, "u64": 18446744073709551615,
    "f32": 0.1, "f64": -2.5e300, "text": "grüße \"quoted\"\n",
    "cell": {"row": 7, "note": "a note longer than any small-string buffer"},
    "triple": [1, -2, 3], "pair": [{"row": 1, "note": "one"}, {"row": 2, "note": "two"}],
    "names": ["left", "right"], "weights": [0.5, 1.25], "cells": [{"row": 3, "note": "three"}],
    "labels": ["a", ""], "bytes": [0, 1, 255]})";
  EXPECT_EQ(json_to_cdr(json, schema_), cdr_of(message));
}

TEST_F(JsonToCdr, FieldsLeftOutTakeTheirZeroValue) {
  const Every zero{};
  EXPECT_EQ(json_to_cdr("{}", schema_), cdr_of(zero));
  Every some{};
  some.cell.row = 4;
  some.pair[1].note = "x";
  EXPECT_EQ(json_to_cdr(R"({"cell": {"row": 4}, "pair": [{}, {"note": "x"}]})", schema_),
            cdr_of(some));
}

TEST_F(JsonToCdr, WhatTheRendererPrintsReadsBackToTheSameBytes) {
  const std::vector<std::uint8_t> cdr = json_to_cdr(
      R"({"f32": 3.4028234e38, "f64": 5e-324, "text": "t", "cells": [{"row": -1}], "u64": 1})",
      schema_);
  const std::size_t size = detail::cdr_block_size(schema_, cdr);
  std::vector<std::byte> block(size + 16);
  auto* aligned =
      reinterpret_cast<std::byte*>((reinterpret_cast<std::uintptr_t>(block.data()) + 15) / 16 * 16);
  detail::cdr_to_block(schema_, cdr, aligned);
  EXPECT_EQ(json_to_cdr(render_message_json(aligned, schema_), schema_), cdr);
}

TEST_F(JsonToCdr, FloatsTakeIntegersAndAnyNumberTheirTypeHolds) {
  Every message{};
  message.f32 = 3.0F;
  message.f64 = -7.0;
  EXPECT_EQ(json_to_cdr(R"({"f32": 3, "f64": -7})", schema_), cdr_of(message));
}

TEST_F(JsonToCdr, UnknownFieldsAreNamedWithTheTypeAndItsFields) {
  EXPECT_EQ(refusal(R"({"flagg": true})"),
            "json_cdr_test/msg/Every: unknown field \"flagg\" of json_cdr_test/msg/Every; its "
            "fields: flag, i8, u8, i16, u16, i32, u32, i64, u64, f32, f64, text, cell, triple, "
            "pair, names, weights, cells, labels, bytes");
  EXPECT_EQ(refusal(R"({"cells": [{}, {"rows": 1}]})"),
            "json_cdr_test/msg/Every: unknown field \"rows\" (in 'cells[1]') of "
            "json_cdr_test/msg/Cell; its fields: row, note");
}

TEST_F(JsonToCdr, IntegersOutOfTheirTypesRangeAreRefused) {
  EXPECT_EQ(refusal(R"({"i8": 128})"),
            "json_cdr_test/msg/Every: field 'i8' 128 does not fit int8 (-128 to 127)");
  EXPECT_EQ(refusal(R"({"i8": -129})"),
            "json_cdr_test/msg/Every: field 'i8' -129 does not fit int8 (-128 to 127)");
  EXPECT_EQ(refusal(R"({"u8": -1})"),
            "json_cdr_test/msg/Every: field 'u8' -1 does not fit uint8 (0 to 255)");
  EXPECT_EQ(refusal(R"({"u16": 65536})"),
            "json_cdr_test/msg/Every: field 'u16' 65536 does not fit uint16 (0 to 65535)");
  EXPECT_NE(refusal(R"({"i32": 2147483648})"), "");
  EXPECT_NE(refusal(R"({"u32": 4294967296})"), "");
  EXPECT_NE(refusal(R"({"i64": 9223372036854775808})"), "");
  EXPECT_NE(refusal(R"({"u64": -1})"), "");
  // Beyond uint64, JSON's number is a float: not an integer at all.
  EXPECT_EQ(refusal(R"({"u64": 18446744073709551616})"),
            "json_cdr_test/msg/Every: field 'u64' takes an integer (uint64), not "
            "1.8446744073709552e+19");
  EXPECT_NE(refusal(R"({"triple": [1, 2, 4294967296]})"), "");
  EXPECT_NE(refusal(R"({"bytes": [256]})").find("'bytes[0]' 256 does not fit uint8"),
            std::string::npos);
}

TEST_F(JsonToCdr, FloatsBeyondTheirTypeAreRefused) {
  EXPECT_EQ(refusal(R"({"f32": 3.5e38})"),
            "json_cdr_test/msg/Every: field 'f32' 3.5e+38 does not fit float32");
  // float32's largest, as printed: a little above it in double, it rounds to it.
  EXPECT_EQ(refusal(R"({"f32": 3.4028235e38})"), "");
  EXPECT_EQ(refusal(R"({"f32": -1e39})"),
            "json_cdr_test/msg/Every: field 'f32' -1e+39 does not fit float32");
  // JSON has no infinity; a literal beyond double's range reads as one.
  EXPECT_NE(refusal(R"({"f64": 1e400})"), "");
  EXPECT_EQ(refusal(R"({"f64": 1e308})"), "");
}

TEST_F(JsonToCdr, ValuesOfAnotherKindAreRefusedNamingWhatTheFieldTakes) {
  EXPECT_EQ(refusal(R"({"flag": 1})"),
            "json_cdr_test/msg/Every: field 'flag' takes true or false, not 1");
  EXPECT_EQ(refusal(R"({"i32": 1.5})"),
            "json_cdr_test/msg/Every: field 'i32' takes an integer (int32), not 1.5");
  EXPECT_EQ(refusal(R"({"i32": "1"})"),
            "json_cdr_test/msg/Every: field 'i32' takes an integer (int32), not \"1\"");
  EXPECT_EQ(refusal(R"({"f64": true})"),
            "json_cdr_test/msg/Every: field 'f64' takes a number (float64), not true");
  EXPECT_EQ(refusal(R"({"text": 3})"),
            "json_cdr_test/msg/Every: field 'text' takes a string, not 3");
  EXPECT_EQ(refusal(R"({"cell": [1]})"),
            "json_cdr_test/msg/Every: field 'cell' takes an object of the fields of "
            "json_cdr_test/msg/Cell, not [1]");
  EXPECT_EQ(refusal(R"({"weights": {"a": 1}})"),
            "json_cdr_test/msg/Every: field 'weights' takes an array, not {\"a\":1}");
  EXPECT_EQ(refusal(R"({"triple": 3})"),
            "json_cdr_test/msg/Every: field 'triple' takes an array, not 3");
  EXPECT_EQ(refusal(R"({"flag": null})"),
            "json_cdr_test/msg/Every: field 'flag' takes true or false, not null");
  EXPECT_EQ(refusal("[1, 2]"),
            "json_cdr_test/msg/Every: the message takes an object of the fields of "
            "json_cdr_test/msg/Every, not [1,2]");
  EXPECT_EQ(refusal(R"({"labels": ["a", 2]})"),
            "json_cdr_test/msg/Every: field 'labels[1]' takes a string, not 2");
  // Long values are cut in the message.
  EXPECT_EQ(refusal(R"({"i8": ")" + std::string(100, 'x') + R"("})"),
            "json_cdr_test/msg/Every: field 'i8' takes an integer (int8), not \"" +
                std::string(36, 'x') + "...");
}

TEST_F(JsonToCdr, FixedArraysHoldExactlyTheirLength) {
  EXPECT_EQ(refusal(R"({"triple": [1, 2]})"),
            "json_cdr_test/msg/Every: field 'triple' holds exactly 3 elements, not 2");
  EXPECT_EQ(refusal(R"({"pair": [{}, {}, {}]})"),
            "json_cdr_test/msg/Every: field 'pair' holds exactly 2 elements, not 3");
}

TEST_F(JsonToCdr, BoundsOfSequencesAndStringsAreChecked) {
  Schema bounded = schema_;
  for (SchemaField& field : bounded.types[0].fields) {
    if (field.name == "weights") field.sequence_bound = 2;
    if (field.name == "text") field.string_bound = 4;
  }
  EXPECT_EQ(refusal(R"({"weights": [1, 2], "text": "four"})", bounded), "");
  EXPECT_EQ(refusal(R"({"weights": [1, 2, 3]})", bounded),
            "json_cdr_test/msg/Every: field 'weights' holds at most 2 elements, not 3");
  // The bound counts bytes, as C++ and CDR do: "ü" is two.
  EXPECT_EQ(refusal(R"({"text": "füűr"})", bounded),
            "json_cdr_test/msg/Every: field 'text' holds at most 4 bytes, not 6");
}

TEST_F(JsonToCdr, StringsHoldingANulAreRefused) {
  EXPECT_EQ(refusal(R"({"text": "a\u0000b"})"),
            "json_cdr_test/msg/Every: field 'text' holds a NUL character, which CDR strings "
            "cannot");
}

TEST_F(JsonToCdr, TextThatIsNoJsonIsRefused) {
  for (const char* text : {"", "{", "{\"flag\": tru}", "{} {}", "{'flag': true}", "\xff"}) {
    EXPECT_EQ(refusal(text).rfind("not JSON: ", 0), 0U) << text;
  }
}

TEST_F(JsonToCdr, SyntaxIsCheckedWithoutTheType) {
  EXPECT_EQ(json_syntax_problem(R"({"anything": [1, {"at": "all"}]})"), "");
  EXPECT_EQ(json_syntax_problem("[]"), "");
  EXPECT_EQ(json_syntax_problem("{").rfind("not JSON: ", 0), 0U);
  EXPECT_EQ(json_syntax_problem(std::string(1000, '[')),
            "the JSON nests deeper than any message (66 levels)");
}

TEST_F(JsonToCdr, DeepNestingIsRefusedWhileParsing) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_EQ(refusal(deep), "the JSON nests deeper than any message (66 levels)");
  std::string objects;
  for (int i = 0; i < 70; ++i) objects += R"({"cell":)";
  objects += "{}" + std::string(70, '}');
  EXPECT_EQ(refusal(objects), "the JSON nests deeper than any message (66 levels)");
}

TEST_F(JsonToCdr, AMessageLongerThanTheLimitIsRefused) {
  const JsonToCdrOptions small{.max_bytes = 256};
  EXPECT_EQ(refusal("{}", schema_, small), "");
  EXPECT_EQ(refusal(R"({"text": ")" + std::string(300, 'x') + R"("})", schema_, small),
            "json_cdr_test/msg/Every: field 'text' makes the message longer than 256 bytes");
  Schema wide = schema_;
  for (SchemaField& field : wide.types[0].fields) {
    if (field.name == "triple") field.array_length = 1'000'000'000;
  }
  EXPECT_EQ(refusal("{}", wide, small),
            "json_cdr_test/msg/Every: field 'triple' makes the message longer than 256 bytes");
}

TEST_F(JsonToCdr, TypesWithoutCdrFormAreRefused) {
  const Schema opaque = parse_schema(schema_of<json_cdr_test::WithOpaque>());
  EXPECT_EQ(refusal(R"({"id": 1})", opaque),
            "json_cdr_test/msg/WithOpaque: field 'raw' holds opaque bytes, which have no CDR form");
  const Schema raw = parse_schema(schema_of<json_cdr_test::Point>());
  EXPECT_NE(refusal("{}", raw).find("describes no fields"), std::string::npos);
}

}  // namespace
}  // namespace agnocast
