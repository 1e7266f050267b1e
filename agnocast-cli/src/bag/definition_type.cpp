#include "bag/definition_type.hpp"

#include <algorithm>
#include <deque>
#include <map>
#include <set>

#include "agnocast/allocator.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/message_traits.hpp"
#include "agnocast/schema.hpp"
#include "cli.hpp"
#include "msg_parser.hpp"

namespace agnocast::cli {
namespace {

// A message's own bytes (containers' elements aside): what a 32-bit size holds.
constexpr std::uint64_t max_type_size = std::uint64_t{1} << 31;

std::size_t align_up(std::size_t value, std::size_t align) {
  return (value + align - 1) / align * align;
}

// "pkg/msg/Name" or "pkg/Name" → {"pkg", "Name"}.
std::pair<std::string, std::string> split_type_name(std::string_view name) {
  const std::size_t first = name.find('/');
  const std::size_t last = name.rfind('/');
  if (first == std::string_view::npos || first == 0 || last + 1 >= name.size() ||
      (last != first && name.substr(first, last - first + 1) != "/msg/")) {
    throw InputError("'" + std::string(name) + "' is not a message type name (pkg/msg/Name)");
  }
  return {std::string(name.substr(0, first)), std::string(name.substr(last + 1))};
}

// Every descriptor and the strings they point at, alive as long as the builder.
class DefinitionTypes {
 public:
  // The definition's first section is the type root_package/root_name.
  DefinitionTypes(std::string_view definition, const std::string& root_package,
                  const std::string& root_name) {
    split(definition, root_package + "/" + root_name);
  }

  const TypeDescriptor& type(const std::string& package, const std::string& name) {
    const std::string key = package + "/" + name;
    if (const auto built = built_.find(key); built != built_.end()) return *built->second;
    if (building_.contains(key)) throw InputError("message type " + key + " contains itself");
    // Each level is a call deeper; readers refuse deeper schemas anyway.
    if (building_.size() >= message_max_nesting) {
      throw InputError("message type " + key + " nests messages more than " +
                       std::to_string(message_max_nesting) + " deep");
    }
    const auto text = texts_.find(key);
    if (text == texts_.end()) {
      throw InputError("the definition has no section for " + key + " (\"MSG: " + key + "\")");
    }
    building_.insert(key);
    msggen::MessageSpec spec;
    try {
      spec = msggen::parse_message(text->second, key + ".msg", package, name);
    } catch (const std::exception& error) {
      throw InputError(std::string("definition of ") + error.what());
    }
    const TypeDescriptor& built = lay_out(spec);
    building_.erase(key);
    built_[key] = &built;
    return built;
  }

 private:
  // The sections of a ros2msg definition: the first is the schema's own type.
  void split(std::string_view definition, std::string key) {
    std::string text;
    const auto flush = [&] {
      texts_.emplace(key, text);  // a type given twice keeps its first text
      text.clear();
    };
    while (!definition.empty()) {
      const std::size_t end = definition.find('\n');
      std::string_view line = definition.substr(0, end);
      definition = end == std::string_view::npos ? std::string_view{} : definition.substr(end + 1);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (line.size() >= 3 && line.find_first_not_of('=') == std::string_view::npos) continue;
      if (line.starts_with("MSG: ")) {
        flush();
        const auto [package, name] = split_type_name(line.substr(5));
        key = package + "/" + name;
        continue;
      }
      text.append(line).append("\n");
    }
    flush();
  }

  struct Element {
    FieldKind kind;
    std::uint32_t size;
    std::uint32_t align;
    const TypeDescriptor* nested = nullptr;
  };

  Element element_of(const msggen::FieldType& field_type) {
    using msggen::BaseType;
    switch (field_type.base) {
      case BaseType::Bool:
        // agnocast::vector<bool> packs bits: msggen makes bool sequences of bytes.
        if (field_type.container == msggen::Container::Sequence) return {FieldKind::UInt8, 1, 1};
        return {FieldKind::Bool, 1, 1};
      case BaseType::Byte:
      case BaseType::Char:
      case BaseType::UInt8:
        return {FieldKind::UInt8, 1, 1};
      case BaseType::Int8:
        return {FieldKind::Int8, 1, 1};
      case BaseType::Int16:
        return {FieldKind::Int16, 2, 2};
      case BaseType::UInt16:
        return {FieldKind::UInt16, 2, 2};
      case BaseType::Int32:
        return {FieldKind::Int32, 4, 4};
      case BaseType::UInt32:
        return {FieldKind::UInt32, 4, 4};
      case BaseType::Int64:
        return {FieldKind::Int64, 8, 8};
      case BaseType::UInt64:
        return {FieldKind::UInt64, 8, 8};
      case BaseType::Float32:
        return {FieldKind::Float32, 4, 4};
      case BaseType::Float64:
        return {FieldKind::Float64, 8, 8};
      case BaseType::String:
        return {FieldKind::String, sizeof(agnocast::string), alignof(agnocast::string)};
      case BaseType::Message: {
        const TypeDescriptor& nested = type(field_type.package, field_type.name);
        return {FieldKind::Message, nested.size, nested.align, &nested};
      }
    }
    throw InputError("unknown field type");
  }

  const TypeDescriptor& lay_out(const msggen::MessageSpec& spec) {
    std::vector<FieldDescriptor>& fields = fields_.emplace_back();
    std::size_t offset = 0;
    std::size_t align = 1;
    const auto add = [&](std::string_view name, const msggen::FieldType& type) {
      const Element element = element_of(type);
      FieldDescriptor field{strings_.emplace_back(name),
                            element.kind,
                            FieldShape::Single,
                            0,
                            element.size,
                            element.size,
                            element.align,
                            0,
                            0,
                            type.string_bound,
                            element.nested};
      std::size_t field_align = element.align;
      if (type.container == msggen::Container::FixedArray) {
        const std::uint64_t bytes = std::uint64_t{element.size} * type.length;
        if (bytes > max_type_size) {
          throw InputError("field '" + std::string(name) + "' takes " + std::to_string(bytes) +
                           " bytes, more than a message may");
        }
        field.shape = FieldShape::Array;
        field.array_length = type.length;
        field.size = static_cast<std::uint32_t>(bytes);
      } else if (type.container == msggen::Container::Sequence) {
        field.shape = FieldShape::Sequence;
        field.sequence_bound = type.length;
        field.size = sizeof(agnocast::vector<std::uint8_t>);
        field_align = alignof(agnocast::vector<std::uint8_t>);
      }
      offset = align_up(offset, field_align);
      field.offset = static_cast<std::uint32_t>(offset);
      offset += field.size;
      align = std::max(align, field_align);
      fields.push_back(field);
    };
    for (const msggen::Field& field : spec.fields) add(field.name, field.type);
    if (spec.fields.empty()) {
      msggen::FieldType byte;
      byte.base = msggen::BaseType::UInt8;
      add("structure_needs_at_least_one_member", byte);
    }
    if (offset > max_type_size) {
      throw InputError(spec.package + "/" + spec.name + " takes " + std::to_string(offset) +
                       " bytes, more than a message may");
    }
    TypeDescriptor& type = types_.emplace_back();
    type.name = strings_.emplace_back(spec.package + "/msg/" + spec.name);
    type.size = static_cast<std::uint32_t>(align_up(offset, align));
    type.align = static_cast<std::uint32_t>(align);
    type.fields = fields;
    type.hash = detail::declared_type_hash(type.name, type.size, type.align, type.fields);
    type.definition = texts_.at(spec.package + "/" + spec.name);  // what the file says of it
    return type;
  }

  std::map<std::string, std::string> texts_;  // "pkg/Name" → its .msg text
  std::map<std::string, const TypeDescriptor*> built_;
  std::set<std::string> building_;
  std::deque<std::string> strings_;
  std::deque<std::vector<FieldDescriptor>> fields_;
  std::deque<TypeDescriptor> types_;
};

}  // namespace

DefinitionType type_from_definition(std::string_view schema_name, std::string_view definition) {
  const auto [package, name] = split_type_name(schema_name);
  DefinitionTypes types(definition, package, name);
  const TypeDescriptor& root = types.type(package, name);
  DefinitionType result;
  result.type_name = std::string(root.name);
  result.type_hash = root.hash;
  try {
    result.schema = build_schema(root);
  } catch (const SchemaError& error) {
    throw InputError(std::string(schema_name) + ": " + error.what());
  }
  return result;
}

}  // namespace agnocast::cli
