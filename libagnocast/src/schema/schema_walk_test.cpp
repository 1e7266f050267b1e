#include "agnocast/schema_walk.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <deque>
#include <string>
#include <vector>

namespace schema_walk_test {

struct Sample {
  std::uint32_t id;
  agnocast::string label;
  agnocast::vector<float> values;
};

}  // namespace schema_walk_test

AGNOCAST_MESSAGE(schema_walk_test::Sample, "schema_walk_test/msg/Sample", id, label, values);

namespace agnocast {
namespace {

using schema_walk_test::Sample;

// A "pool": the only bytes a checked reader may touch; a Sample's words are
// written into it by hand, as another process could write them.
class ForeignSample : public ::testing::Test {
 protected:
  void SetUp() override {
    schema_ = parse_schema(schema_of<Sample>());
    pool_.assign(4096, std::byte{0});
    message_ = pool_.data() + 64;
    floats_ = reinterpret_cast<std::uintptr_t>(pool_.data() + 1024);
  }
  const SchemaField& field(const std::string& name) const {
    for (const SchemaField& f : schema_.types[0].fields) {
      if (f.name == name) return f;
    }
    throw std::logic_error("no field " + name);
  }
  void write_words(const std::string& name, std::uint8_t first_offset, std::uintptr_t first,
                   std::uint8_t second_offset, std::uintptr_t second) {
    std::byte* at = message_ + field(name).offset;
    std::memcpy(at + first_offset, &first, sizeof first);
    std::memcpy(at + second_offset, &second, sizeof second);
  }
  void vector_words(std::uintptr_t begin, std::uintptr_t end) {
    write_words("values", schema_.containers.vector_begin_offset, begin,
                schema_.containers.vector_end_offset, end);
  }
  void string_words(std::uintptr_t data, std::size_t length) {
    write_words("label", schema_.containers.string_data_offset, data,
                schema_.containers.string_length_offset, length);
  }
  ForeignElements values() const {
    return field_elements(schema_.containers, field("values"), message_ + field("values").offset,
                          memory());
  }
  ForeignText label() const {
    return string_text(schema_.containers, field("label"), message_ + field("label").offset,
                       memory());
  }
  ForeignMemory memory() const { return ForeignMemory(std::span<const std::byte>(pool_)); }

  Schema schema_;
  std::vector<std::byte> pool_;
  std::byte* message_ = nullptr;
  std::uintptr_t floats_ = 0;
};

TEST_F(ForeignSample, ReadsContainersInsideThePool) {
  vector_words(floats_, floats_ + 3 * sizeof(float));
  const ForeignElements found = values();
  EXPECT_EQ(found.problem, nullptr);
  EXPECT_EQ(found.count, 3u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(found.first), floats_);
  string_words(floats_, 5);
  EXPECT_EQ(label().problem, nullptr);
  EXPECT_EQ(label().text.size(), 5u);
  vector_words(0, 0);
  EXPECT_EQ(values().problem, nullptr);
  EXPECT_EQ(values().count, 0u);
}

TEST_F(ForeignSample, RefusesEveryLieASequenceCanTell) {
  const auto outside = reinterpret_cast<std::uintptr_t>(pool_.data() + pool_.size());
  const struct {
    std::uintptr_t begin, end;
    std::string problem;
  } lies[] = {
      {0x10000, 0x10000 + 64, "sequence outside the publisher's pool"},
      {floats_, floats_ + (std::uintptr_t{1} << 40), "sequence outside the publisher's pool"},
      {outside - 8, outside + 8, "sequence outside the publisher's pool"},
      // A count whose bytes wrap the address space.
      {floats_, floats_ - 4, "sequence ends before its begin"},
      {~std::uintptr_t{0} - 7, ~std::uintptr_t{0} - 3, "sequence outside the publisher's pool"},
      {floats_ + 1, floats_ + 9, "misaligned sequence"},
      {floats_, floats_ + 6, "sequence length is no whole number of elements"},
  };
  for (const auto& lie : lies) {
    vector_words(lie.begin, lie.end);
    const ForeignElements found = values();
    ASSERT_NE(found.problem, nullptr) << lie.problem;
    EXPECT_EQ(found.problem, lie.problem);
    EXPECT_EQ(found.count, 0u);
  }
}

TEST_F(ForeignSample, RefusesStringsOutsideThePool) {
  string_words(0x10000, 5);
  EXPECT_STREQ(label().problem, "string outside the publisher's pool");
  string_words(floats_, std::size_t{1} << 40);
  EXPECT_STREQ(label().problem, "string outside the publisher's pool");
  string_words(~std::uintptr_t{0} - 2, 8);
  EXPECT_STREQ(label().problem, "string outside the publisher's pool");
}

TEST_F(ForeignSample, ChecksTheMessageItself) {
  const SchemaType& type = schema_.types[0];
  EXPECT_EQ(message_problem(type, message_, memory()), nullptr);
  EXPECT_STREQ(message_problem(type, pool_.data() + pool_.size() - 4, memory()),
               "message outside the publisher's pool");
  EXPECT_STREQ(message_problem(type, message_ + 1, memory()), "misaligned message");
  // Trusted memory: an address of this process is not checked against a pool.
  const Sample local{};
  EXPECT_EQ(message_problem(type, &local, ForeignMemory()), nullptr);
  EXPECT_STREQ(message_problem(type, &local, memory()), "message outside the publisher's pool");
}

// Counts what a walk visits: every consumer sees the same checked values.
struct Counter {
  int messages = 0, scalars = 0, elements = 0, texts = 0, problems = 0;
  void begin_message(const SchemaType&) { ++messages; }
  void end_message(const SchemaType&) {}
  void begin_field(const SchemaField&) {}
  void end_field(const SchemaField&) {}
  void scalar(const SchemaField&, const std::byte*) { ++scalars; }
  void numbers(const SchemaField&, const std::byte*, std::size_t count) {
    elements += static_cast<int>(count);
  }
  void opaque(const SchemaField&, const std::byte*, std::size_t) {}
  void text(const SchemaField&, const ForeignText& found) {
    ++texts;
    if (found.problem) ++problems;
  }
  bool begin_elements(const SchemaField&, const ForeignElements& found) {
    if (found.problem) ++problems;
    return true;
  }
  void begin_element(const SchemaField&, std::size_t) {}
  void end_elements(const SchemaField&) {}
};

TEST_F(ForeignSample, TheWalkHandsOnlyCheckedContainersToItsVisitor) {
  vector_words(floats_, floats_ + 2 * sizeof(float));
  string_words(floats_, 3);
  Counter counter;
  SchemaWalk<Counter>(schema_, memory(), counter).message(schema_.types[0], message_);
  EXPECT_EQ(counter.messages, 1);
  EXPECT_EQ(counter.scalars, 1);
  EXPECT_EQ(counter.elements, 2);
  EXPECT_EQ(counter.texts, 1);
  EXPECT_EQ(counter.problems, 0);

  vector_words(0x10000, 0x10000 + 8);
  string_words(0x10000, 3);
  Counter refused;
  SchemaWalk<Counter>(schema_, memory(), refused).message(schema_.types[0], message_);
  EXPECT_EQ(refused.elements, 0);  // the visitor never got the elements
  EXPECT_EQ(refused.problems, 2);
}

// A chain of message types, each holding the next: Level0 { Level1 inner; } ...
struct Chain {
  explicit Chain(std::size_t depth) : types(depth), fields(depth), names(depth) {
    for (std::size_t i = depth; i-- > 0;) {
      names[i] = "chain/msg/Level" + std::to_string(i);
      types[i].name = names[i];
      types[i].size = 4;
      types[i].align = 4;
      types[i].hash = i + 1;
      if (i + 1 < depth) {
        fields[i] = {"inner", FieldKind::Message, FieldShape::Single, 0, 4, 4, 4, 0, 0,
                     0,       &types[i + 1]};
      } else {
        fields[i] = {"value", FieldKind::UInt32, FieldShape::Single, 0, 4, 4, 4, 0, 0, 0, nullptr};
      }
      types[i].fields = std::span<const FieldDescriptor>(&fields[i], 1);
    }
  }
  std::deque<TypeDescriptor> types;
  std::deque<FieldDescriptor> fields;
  std::deque<std::string> names;
};

TEST(SchemaNesting, IsBoundedWhereTheSchemaIsBuiltAndWhereItIsRead) {
  EXPECT_NO_THROW(parse_schema(build_schema(Chain(message_max_nesting).types[0])));
  const Chain deep(message_max_nesting + 1);
  try {
    build_schema(deep.types[0]);
    ADD_FAILURE() << "a schema nesting " << message_max_nesting + 1 << " deep was built";
  } catch (const SchemaError& error) {
    EXPECT_NE(std::string(error.what()).find("nests messages 33 deep"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace agnocast
