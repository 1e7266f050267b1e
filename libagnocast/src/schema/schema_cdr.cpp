#include "agnocast/schema_cdr.hpp"

#include <algorithm>
#include <cstring>

#include "agnocast/schema_walk.hpp"

namespace agnocast {
namespace {

// Writes the CDR form of a message as SchemaWalk visits it.
class SchemaCdrWriter {
 public:
  SchemaCdrWriter(const SchemaCdrOptions& options, std::vector<std::uint8_t>& out)
      : options_(options), out_(out), writer_(out) {}

  void begin_message(const SchemaType&) {}
  void end_message(const SchemaType&) {}
  void begin_field(const SchemaField&) {}
  void end_field(const SchemaField& field) { check_size(field); }

  void scalar(const SchemaField& field, const std::byte* at) { numbers(field, at, 1); }
  void numbers(const SchemaField& field, const std::byte* first, std::size_t count) {
    switch (field.kind) {
      case FieldKind::Bool:  // one byte, as in memory
      case FieldKind::UInt8:
        return primitives<std::uint8_t>(first, count);
      case FieldKind::Int8:
        return primitives<std::int8_t>(first, count);
      case FieldKind::Int16:
        return primitives<std::int16_t>(first, count);
      case FieldKind::UInt16:
        return primitives<std::uint16_t>(first, count);
      case FieldKind::Int32:
        return primitives<std::int32_t>(first, count);
      case FieldKind::UInt32:
        return primitives<std::uint32_t>(first, count);
      case FieldKind::Int64:
        return primitives<std::int64_t>(first, count);
      case FieldKind::UInt64:
        return primitives<std::uint64_t>(first, count);
      case FieldKind::Float32:
        return primitives<float>(first, count);
      case FieldKind::Float64:
        return primitives<double>(first, count);
      default:
        fail(field, "not a number");
    }
  }
  void opaque(const SchemaField& field, const std::byte*, std::size_t) {
    fail(field, "opaque bytes without a field description have no CDR form");
  }
  void text(const SchemaField& field, const ForeignText& found) {
    if (found.problem) fail(field, found.problem);
    if (found.text.size() >= 0xFFFFFFFFu) fail(field, "string longer than CDR can count");
    writer_.write(static_cast<std::uint32_t>(found.text.size() + 1));
    if (!found.text.empty()) writer_.write_elements(found.text.data(), found.text.size());
    writer_.write('\0');
  }

  bool begin_elements(const SchemaField& field, const ForeignElements& found) {
    if (found.problem) fail(field, found.problem);
    if (field.shape == FieldShape::Sequence) {
      if (found.count > 0xFFFFFFFFu) fail(field, "sequence longer than CDR can count");
      writer_.write(static_cast<std::uint32_t>(found.count));
    }
    return true;
  }
  void begin_element(const SchemaField& field, std::size_t) {
    if (field.kind == FieldKind::Message) check_size(field);
  }
  void end_elements(const SchemaField&) {}

 private:
  [[noreturn]] static void fail(const SchemaField& field, const std::string& problem) {
    throw cdr::Error("field '" + field.name + "': " + problem);
  }
  // Containers that alias one another could multiply the output without bound.
  void check_size(const SchemaField& field) const {
    if (out_.size() > options_.max_bytes) fail(field, "more bytes than a message may produce");
  }

  template <class T>
  void primitives(const std::byte* at, std::size_t count) {
    if (count == 1) {
      writer_.write(load_unaligned<T>(at));
    } else if (count > 0) {
      // In place in the pool, aligned as T (checked by field_elements or the schema's layout).
      writer_.write_elements(reinterpret_cast<const T*>(at), count);
    }
  }

  const SchemaCdrOptions& options_;
  std::vector<std::uint8_t>& out_;
  cdr::Writer writer_;
};

}  // namespace

void serialize_with_schema(const void* message, const Schema& schema,
                           std::vector<std::uint8_t>& out, const SchemaCdrOptions& options) {
  out.assign(cdr::encapsulation_header.begin(), cdr::encapsulation_header.end());
  const SchemaType& root = schema.types.at(0);
  if (root.fields.empty()) {
    throw cdr::Error("type " + root.name + " describes no fields, so it has no CDR form");
  }
  const ForeignMemory memory =
      options.readable ? ForeignMemory(*options.readable) : ForeignMemory();
  if (const char* problem = message_problem(root, message, memory)) {
    throw cdr::Error(root.name + ": " + problem);
  }
  SchemaCdrWriter writer(options, out);
  SchemaWalk<SchemaCdrWriter>(schema, memory, writer)
      .message(root, static_cast<const std::byte*>(message));
}

}  // namespace agnocast
