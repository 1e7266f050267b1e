#include "agnocast/schema.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace schema_test {

struct Point {
  float x;
  float y;
};

struct Track {
  std::uint32_t id;
  agnocast::string label;
  Point last;
  agnocast::vector<Point> history;
  std::array<Point, 2> box;
  agnocast::vector<agnocast::string> tags;
};

// More fields than a shallow preprocessor loop would reach.
struct Wide {
  std::uint8_t f0, f1, f2, f3, f4, f5, f6, f7, f8, f9, f10, f11, f12, f13, f14, f15, f16, f17, f18,
      f19, f20, f21, f22, f23, f24, f25, f26, f27, f28, f29, f30, f31, f32, f33, f34, f35, f36, f37,
      f38, f39;
};

}  // namespace schema_test

AGNOCAST_MESSAGE(schema_test::Wide, "schema_test/msg/Wide", f0, f1, f2, f3, f4, f5, f6, f7, f8, f9,
                 f10, f11, f12, f13, f14, f15, f16, f17, f18, f19, f20, f21, f22, f23, f24, f25,
                 f26, f27, f28, f29, f30, f31, f32, f33, f34, f35, f36, f37, f38, f39);
AGNOCAST_MESSAGE(schema_test::Point, "schema_test/msg/Point", x, y);
AGNOCAST_MESSAGE(schema_test::Track, "schema_test/msg/Track", id, label, last, history, box, tags);

namespace agnocast {
namespace {

using schema_test::Point;
using schema_test::Track;

TEST(Schema, RoundTripsEveryTypeAndField) {
  const std::span<const std::uint8_t> blob = schema_of<Track>();
  const Schema schema = parse_schema(blob);
  ASSERT_EQ(schema.types.size(), 2u);
  const SchemaType& track = schema.types[0];
  EXPECT_EQ(track.name, "schema_test/msg/Track");
  EXPECT_EQ(track.hash, message_traits<Track>::type_hash);
  EXPECT_EQ(track.size, sizeof(Track));
  EXPECT_EQ(track.align, alignof(Track));
  ASSERT_EQ(track.fields.size(), 6u);
  const SchemaField& history = track.fields[3];
  EXPECT_EQ(history.name, "history");
  EXPECT_EQ(history.kind, FieldKind::Message);
  EXPECT_EQ(history.shape, FieldShape::Sequence);
  EXPECT_EQ(history.offset, offsetof(Track, history));
  EXPECT_EQ(history.size, sizeof(agnocast::vector<Point>));
  EXPECT_EQ(history.element_size, sizeof(Point));
  EXPECT_EQ(history.nested, 1u);
  EXPECT_EQ(track.fields[4].array_length, 2u);
  EXPECT_EQ(track.fields[4].nested, 1u);  // Point once, used three times
  EXPECT_EQ(schema.types[1].name, "schema_test/msg/Point");
  EXPECT_EQ(schema.types[1].fields[1].kind, FieldKind::Float32);
  EXPECT_EQ(schema.containers.vector_size, sizeof(agnocast::vector<int>));
  EXPECT_EQ(schema.containers.string_size, sizeof(agnocast::string));
}

TEST(Schema, AgnocastMessageTakesManyFields) {
  const auto& fields = message_traits<schema_test::Wide>::fields;
  ASSERT_EQ(fields.size(), 40u);
  EXPECT_EQ(fields[39].name, "f39");
  EXPECT_EQ(fields[39].offset, offsetof(schema_test::Wide, f39));
}

TEST(Schema, HeaderIsVersionedAndSized) {
  const std::span<const std::uint8_t> blob = schema_of<Track>();
  std::uint32_t magic;
  std::memcpy(&magic, blob.data(), 4);
  EXPECT_EQ(magic, schema_magic);
  EXPECT_EQ(blob[0], 'A');
  EXPECT_EQ(blob[4] | blob[5] << 8, schema_format_version);
  EXPECT_EQ(blob[8] | blob[9] << 8 | blob[10] << 16 | blob[11] << 24, blob.size());
  EXPECT_LE(blob.size(), schema_max_bytes);
}

TEST(Schema, ContainerLayoutIsFoundInThisStandardLibrary) {
  const ContainerLayout& layout = native_container_layout();
  agnocast::vector<int> empty;
  std::vector<int> probe(5);
  // The begin and end words are distinct, inside the object, pointer-aligned.
  EXPECT_NE(layout.vector_begin_offset, layout.vector_end_offset);
  EXPECT_EQ(layout.vector_begin_offset % sizeof(void*), 0u);
  EXPECT_LE(layout.vector_end_offset + sizeof(void*), sizeof(empty));
  EXPECT_NE(layout.string_data_offset, layout.string_length_offset);
  const char* data;
  std::memcpy(&data, reinterpret_cast<const char*>(&probe) + layout.vector_begin_offset,
              sizeof(data));
  EXPECT_EQ(static_cast<const void*>(data), static_cast<const void*>(probe.data()));
}

TEST(Schema, RawTypeHasNoFields) {
  struct Pair {
    int a;
    int b;
  };
  const Schema schema = parse_schema(schema_of<Pair>());
  ASSERT_EQ(schema.types.size(), 1u);
  EXPECT_EQ(schema.types[0].name, "raw:8:4");
  EXPECT_TRUE(schema.types[0].fields.empty());
}

// parse_schema's message for `blob` after `corrupt` changed it, or "" when accepted.
template <class Corrupt>
std::string error_after(Corrupt corrupt) {
  const std::span<const std::uint8_t> good = schema_of<Track>();
  std::vector<std::uint8_t> blob(good.begin(), good.end());
  corrupt(blob);
  try {
    parse_schema(blob);
  } catch (const SchemaError& error) {
    return error.what();
  }
  return "";
}

// Offsets inside the blob of Track's first field record.
constexpr std::size_t first_type = 20;
constexpr std::size_t first_field = first_type + 19 + sizeof("schema_test/msg/Track") - 1;
constexpr std::size_t id_kind = first_field + 1 + 2;
constexpr std::size_t id_offset = id_kind + 4;

TEST(Schema, RejectsCorruptBlobsSayingWhy) {
  EXPECT_EQ(error_after([](auto&) {}), "");
  EXPECT_EQ(error_after([](auto& b) { b[0] = 'X'; }), "schema: bad magic (not an agnocast schema)");
  EXPECT_EQ(error_after([](auto& b) { b[4] = 1; }),
            "schema: format version 1, this reader knows 2");
  EXPECT_EQ(error_after([](auto& b) { b.pop_back(); }),
            "schema: total_bytes differs from the blob size");
  EXPECT_EQ(error_after([](auto& b) { b[6] = 0xFF; }), "schema: truncated");
  EXPECT_EQ(error_after([](auto& b) { b[id_kind] = 99; }),
            "schema: schema_test/msg/Track.id: unknown kind");
  EXPECT_EQ(
      error_after([](auto& b) { b[id_kind] = static_cast<std::uint8_t>(FieldKind::Float64); }),
      "schema: schema_test/msg/Track.id: element size does not match its kind");
  EXPECT_EQ(error_after([](auto& b) { b[id_offset + 1] = 0x10; }),
            "schema: schema_test/msg/Track.id: field beyond the end of its type");
  EXPECT_EQ(error_after([](auto& b) { b[first_field + 1] = 0x01; }),
            "schema: a name is empty or not printable");
  // Point's definition length, the blob's last word: past the end.
  EXPECT_EQ(error_after([](auto& b) { b[b.size() - 4] = 5; }), "schema: truncated");
  EXPECT_EQ(error_after([](auto& b) {
              b.insert(b.end(), {0, 0, 0, 0});
            }),
            "schema: total_bytes differs from the blob size");
}

// Track as agnocast-msggen would describe it: with its .msg text.
TypeDescriptor track_with_definition(std::string_view definition) {
  TypeDescriptor track = message_traits<Track>::descriptor;
  track.definition = definition;
  return track;
}

TEST(Schema, DefinitionsTravelWithTheirTypes) {
  const std::string text = "# a track\nuint8 KIND=1\nuint32 id\nstring label  # shown\n";
  const std::vector<std::uint8_t> blob = build_schema(track_with_definition(text));
  const Schema schema = parse_schema(blob);
  ASSERT_EQ(schema.types.size(), 2u);
  EXPECT_EQ(schema.types[0].definition, text);
  EXPECT_EQ(schema.types[1].definition, "");  // Point, declared in C++
  // The text is not the layout: the hash stays the type's.
  EXPECT_EQ(schema.types[0].hash, message_traits<Track>::type_hash);
}

TEST(Schema, DefinitionsThatCannotTravelAreLeftOut) {
  // Too large for the kernel's bound: the fields still make a schema.
  const std::string huge(schema_max_bytes, '#');
  const Schema without = parse_schema(build_schema(track_with_definition(huge)));
  EXPECT_EQ(without.types[0].definition, "");
  EXPECT_EQ(without.types[0].fields.size(), 6u);
  // A NUL would cut the text short for whoever reads it as a C string.
  const std::string with_nul("uint32 id\0string label\n", 24);
  EXPECT_EQ(parse_schema(build_schema(track_with_definition(with_nul))).types[0].definition, "");
  // ... and a blob that carries one anyway is refused.
  std::vector<std::uint8_t> blob = build_schema(track_with_definition("a#b\n"));
  const std::string text = "a#b\n";
  const auto at = std::search(blob.begin(), blob.end(), text.begin(), text.end());
  ASSERT_NE(at, blob.end());
  *(at + 1) = 0;
  try {
    parse_schema(blob);
    ADD_FAILURE() << "a definition holding NUL was accepted";
  } catch (const SchemaError& error) {
    EXPECT_STREQ(error.what(), "schema: a definition holds NUL");
  }
}

TEST(Schema, NestedIndexMustPointForward) {
  // The `last` field's nested index (after its name, kind and shape) pointed back at Track.
  EXPECT_EQ(error_after([](auto& b) {
              const std::string name = "last";
              const auto at = std::search(b.begin(), b.end(), name.begin(), name.end());
              ASSERT_NE(at, b.end());
              const auto nested = static_cast<std::size_t>(at - b.begin()) + name.size() + 2;
              ASSERT_EQ(b[nested], 1u);
              b[nested] = 0;
            }),
            "schema: schema_test/msg/Track.last: nested type index out of order");
}

}  // namespace
}  // namespace agnocast
