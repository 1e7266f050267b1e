// `service call`'s JSON as a user types it: json_to_cdr() accepts it or
// throws JsonInputError, whatever the text. What it accepts is a message of
// the type (the CDR reader builds it), which renders as JSON that it accepts
// again, and which after that one normalization (-0 reads back as 0) writes
// the same bytes every time. The first byte picks the type: every field kind
// and shape; the same with bounds; messages nested three deep in arrays and
// sequences.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/json_to_cdr.hpp"
#include "agnocast/message_render.hpp"
#include "agnocast/schema.hpp"
#include "schema/cdr_to_pool.hpp"

namespace json_fuzz {

struct Cell {
  std::int16_t row;
  agnocast::string note;
};

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

struct Leaf {
  agnocast::string name;
  std::uint32_t id;
};

struct Branch {
  std::array<Leaf, 2> pair;
  agnocast::vector<Leaf> leaves;
};

struct Tree {
  Branch trunk;
  agnocast::vector<Branch> branches;
  double height;
};

}  // namespace json_fuzz

AGNOCAST_MESSAGE(json_fuzz::Cell, "json_fuzz/msg/Cell", row, note);
AGNOCAST_MESSAGE(json_fuzz::Every, "json_fuzz/msg/Every", flag, i8, u8, i16, u16, i32, u32, i64,
                 u64, f32, f64, text, cell, triple, pair, names, weights, cells, labels, bytes);
AGNOCAST_MESSAGE(json_fuzz::Leaf, "json_fuzz/msg/Leaf", name, id);
AGNOCAST_MESSAGE(json_fuzz::Branch, "json_fuzz/msg/Branch", pair, leaves);
AGNOCAST_MESSAGE(json_fuzz::Tree, "json_fuzz/msg/Tree", trunk, branches, height);

namespace {

std::vector<agnocast::Schema> make_schemas() {
  std::vector<agnocast::Schema> schemas;
  schemas.push_back(agnocast::parse_schema(agnocast::schema_of<json_fuzz::Every>()));
  agnocast::Schema bounded = schemas.back();
  for (agnocast::SchemaField& field : bounded.types[0].fields) {
    if (field.name == "weights") field.sequence_bound = 2;
    if (field.name == "labels") field.sequence_bound = 3;
    if (field.name == "text") field.string_bound = 4;
  }
  schemas.push_back(bounded);
  schemas.push_back(agnocast::parse_schema(agnocast::schema_of<json_fuzz::Tree>()));
  return schemas;
}

// Dies (a finding) unless `cdr` is a message of the schema; returns it rendered.
std::string rendered(const agnocast::Schema& schema, const std::vector<std::uint8_t>& cdr) {
  std::size_t size = 0;
  try {
    size = agnocast::detail::cdr_block_size(schema, cdr);
  } catch (const std::exception&) {
    std::abort();  // json_to_cdr wrote what the CDR reader refuses
  }
  const std::size_t align = agnocast::detail::cdr_block_align(schema);
  auto* block = static_cast<std::byte*>(::operator new(size, std::align_val_t{align}));
  agnocast::detail::cdr_to_block(schema, cdr, block);
  std::string text = agnocast::render_message_json(block, schema);
  ::operator delete(block, std::align_val_t{align});
  return text;
}

std::vector<std::uint8_t> accepted(std::string_view json, const agnocast::Schema& schema,
                                   const agnocast::JsonToCdrOptions& options) {
  try {
    return agnocast::json_to_cdr(json, schema, options);
  } catch (const agnocast::JsonInputError&) {
    std::abort();  // what the renderer printed is refused
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<agnocast::Schema> schemas = make_schemas();
  if (size == 0) return 0;
  const agnocast::Schema& schema = schemas[data[0] % schemas.size()];
  const std::string_view json(reinterpret_cast<const char*>(data + 1), size - 1);
  const agnocast::JsonToCdrOptions options{.max_bytes = 1 << 20};
  std::vector<std::uint8_t> cdr;
  try {
    cdr = agnocast::json_to_cdr(json, schema, options);
  } catch (const agnocast::JsonInputError&) {
    return 0;
  }
  const std::vector<std::uint8_t> normal = accepted(rendered(schema, cdr), schema, options);
  if (accepted(rendered(schema, normal), schema, options) != normal) std::abort();
  return 0;
}
