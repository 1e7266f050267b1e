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

const char* primitive_name(FieldKind kind) {
  switch (kind) {
    case FieldKind::Bool:
      return "bool";
    case FieldKind::Int8:
      return "int8";
    case FieldKind::UInt8:
      return "uint8";
    case FieldKind::Int16:
      return "int16";
    case FieldKind::UInt16:
      return "uint16";
    case FieldKind::Int32:
      return "int32";
    case FieldKind::UInt32:
      return "uint32";
    case FieldKind::Int64:
      return "int64";
    case FieldKind::UInt64:
      return "uint64";
    case FieldKind::Float32:
      return "float32";
    case FieldKind::Float64:
      return "float64";
    case FieldKind::String:
      return "string";
    case FieldKind::Message:
    case FieldKind::Opaque:
      break;
  }
  return nullptr;
}

std::string type_fields(const Schema& schema, const SchemaType& type) {
  if (type.fields.empty()) {
    throw cdr::Error("type " + type.name + " describes no fields, so it has no .msg form");
  }
  std::string text;
  for (const SchemaField& field : type.fields) {
    if (field.kind == FieldKind::Message) {
      text += ros2msg_type_name(schema.types[field.nested].name);
    } else if (const char* name = primitive_name(field.kind)) {
      text += name;
      if (field.kind == FieldKind::String && field.string_bound != 0) {
        text += "<=";
        text += std::to_string(field.string_bound);
      }
    } else {
      throw cdr::Error("field '" + field.name + "' of " + type.name +
                       " holds opaque bytes, which have no .msg form");
    }
    // Appended piece by piece: GCC 12 at -O3 misreads "[" + std::string as overlapping.
    if (field.shape == FieldShape::Array) {
      text += '[';
      text += std::to_string(field.array_length);
      text += ']';
    } else if (field.shape == FieldShape::Sequence) {
      text += field.sequence_bound != 0 ? "[<=" : "[";
      if (field.sequence_bound != 0) text += std::to_string(field.sequence_bound);
      text += ']';
    }
    text += ' ';
    text += field.name;
    text += '\n';
  }
  return text;
}

void collect_dependencies(const Schema& schema, const SchemaType& type, std::vector<bool>& seen,
                          std::vector<std::uint16_t>& order) {
  for (const SchemaField& field : type.fields) {
    if (field.kind != FieldKind::Message || seen[field.nested]) continue;
    seen[field.nested] = true;
    order.push_back(field.nested);
    collect_dependencies(schema, schema.types[field.nested], seen, order);
  }
}

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

std::string ros2msg_type_name(std::string_view type_name) {
  const std::size_t slash = type_name.find("/msg/");
  if (slash == std::string_view::npos) return std::string(type_name);
  return std::string(type_name.substr(0, slash)) + "/" + std::string(type_name.substr(slash + 5));
}

std::string ros2msg_definition(const Schema& schema) { return ros2msg_definition(schema, {}); }

std::vector<std::string> msg_text_field_names(std::string_view text) {
  std::vector<std::string> names;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
    if (const std::size_t comment = line.find('#'); comment != std::string_view::npos) {
      line = line.substr(0, comment);
    }
    std::vector<std::string_view> tokens;
    for (std::size_t at = 0; at < line.size();) {
      const std::size_t start = line.find_first_not_of(" \t\r", at);
      if (start == std::string_view::npos) break;
      const std::size_t stop = std::min(line.find_first_of(" \t\r", start), line.size());
      tokens.push_back(line.substr(start, stop - start));
      at = stop;
    }
    if (tokens.size() < 2) continue;
    // "TYPE NAME=VALUE" or "TYPE NAME = VALUE": a constant ("<=" is a bound, in the type).
    if (tokens[1].find('=') != std::string_view::npos) continue;
    if (tokens.size() > 2 && tokens[2].front() == '=') continue;
    names.emplace_back(tokens[1]);
  }
  return names;
}

namespace {

// The type's own .msg text when text_of knows it and its fields are the
// schema's; else its fields written from the schema.
std::string type_text(const Schema& schema, const SchemaType& type, const MsgTextLookup& text_of) {
  if (text_of) {
    if (const std::string_view* known = text_of(type.name)) {
      const std::vector<std::string> names = msg_text_field_names(*known);
      const bool same = names.size() == type.fields.size() &&
                        std::equal(names.begin(), names.end(), type.fields.begin(),
                                   [](const std::string& name, const SchemaField& field) {
                                     return name == field.name;
                                   });
      if (same && !known->empty()) {
        std::string text(*known);
        if (text.back() != '\n') text += '\n';
        return text;
      }
    }
  }
  return type_fields(schema, type);
}

}  // namespace

std::string ros2msg_definition(const Schema& schema, const MsgTextLookup& text_of) {
  const SchemaType& root = schema.types.at(0);
  std::string text = type_text(schema, root, text_of);
  std::vector<bool> seen(schema.types.size(), false);
  std::vector<std::uint16_t> order;
  collect_dependencies(schema, root, seen, order);
  for (const std::uint16_t index : order) {
    text += std::string(80, '=');
    text += "\nMSG: " + ros2msg_type_name(schema.types[index].name) + "\n";
    text += type_text(schema, schema.types[index], text_of);
  }
  return text;
}

}  // namespace agnocast
