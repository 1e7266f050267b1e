#include "agnocast/schema_definition.hpp"

#include <algorithm>

#include "agnocast/cdr.hpp"

namespace agnocast {
namespace {

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

std::string ros2msg_type_name(std::string_view type_name) {
  const std::size_t slash = type_name.find("/msg/");
  if (slash == std::string_view::npos) return std::string(type_name);
  return std::string(type_name.substr(0, slash)) + "/" + std::string(type_name.substr(slash + 5));
}

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

// Whether a .msg text declares the schema type's fields, by name and in order.
// A message without fields has one in C++, as in every ROS 2 language:
// structure_needs_at_least_one_member, which its text does not declare.
bool declares_fields_of(std::string_view text, const SchemaType& type) {
  const std::vector<std::string> names = msg_text_field_names(text);
  if (names.empty() && type.fields.size() == 1 &&
      type.fields[0].name == "structure_needs_at_least_one_member") {
    return true;
  }
  return std::equal(
      names.begin(), names.end(), type.fields.begin(), type.fields.end(),
      [](const std::string& name, const SchemaField& field) { return name == field.name; });
}

// The type's own .msg text when its fields are the schema's; else its fields
// written from the schema.
std::string type_text(const Schema& schema, const SchemaType& type) {
  if (!type.definition.empty() && declares_fields_of(type.definition, type)) {
    std::string text = type.definition;
    if (text.back() != '\n') text += '\n';
    return text;
  }
  return type_fields(schema, type);
}

}  // namespace

std::string ros2msg_definition(const Schema& schema) {
  const SchemaType& root = schema.types.at(0);
  std::string text = type_text(schema, root);
  std::vector<bool> seen(schema.types.size(), false);
  std::vector<std::uint16_t> order;
  collect_dependencies(schema, root, seen, order);
  for (const std::uint16_t index : order) {
    text += std::string(80, '=');
    text += "\nMSG: " + ros2msg_type_name(schema.types[index].name) + "\n";
    text += type_text(schema, schema.types[index]);
  }
  return text;
}

}  // namespace agnocast
