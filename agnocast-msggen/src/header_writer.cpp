#include "header_writer.hpp"

#include <fmt/format.h>

#include <cctype>
#include <initializer_list>
#include <set>

namespace msggen {
namespace {

std::string_view primitive_cpp(BaseType base) {
  switch (base) {
    case BaseType::Bool:
      return "bool";
    case BaseType::Int8:
      return "std::int8_t";
    case BaseType::Int16:
      return "std::int16_t";
    case BaseType::UInt16:
      return "std::uint16_t";
    case BaseType::Int32:
      return "std::int32_t";
    case BaseType::UInt32:
      return "std::uint32_t";
    case BaseType::Int64:
      return "std::int64_t";
    case BaseType::UInt64:
      return "std::uint64_t";
    case BaseType::Float32:
      return "float";
    case BaseType::Float64:
      return "double";
    default:  // byte, char, uint8
      return "std::uint8_t";
  }
}

std::string element_cpp(const FieldType& type) {
  if (type.base == BaseType::String) return "agnocast::string";
  if (type.base == BaseType::Message) return fmt::format("{}::msg::{}", type.package, type.name);
  // agnocast::vector<bool> packs bits, which no reader in another process can follow.
  if (type.base == BaseType::Bool && type.container == Container::Sequence) return "std::uint8_t";
  return std::string(primitive_cpp(type.base));
}

std::string field_cpp(const FieldType& type) {
  switch (type.container) {
    case Container::FixedArray:
      return fmt::format("std::array<{}, {}>", element_cpp(type), type.length);
    case Container::Sequence:
      return fmt::format("agnocast::vector<{}>", element_cpp(type));
    case Container::None:
      break;
  }
  return element_cpp(type);
}

void write_comments(std::string& out, const std::vector<std::string>& comments,
                    std::string_view indent) {
  for (const std::string& comment : comments) {
    out += fmt::format("{}//{}{}\n", indent, comment.empty() ? "" : " ", comment);
  }
}

std::string full_name(const MessageSpec& spec) {
  return fmt::format("{}::{}::{}", spec.package, spec.kind, spec.name);
}

void write_struct(std::string& out, const MessageSpec& spec) {
  write_comments(out, spec.comments, "");
  out += fmt::format("struct {} {{\n", spec.name);
  for (const Constant& constant : spec.constants) {
    write_comments(out, constant.comments, "  ");
    const std::string type = constant.type.base == BaseType::String
                                 ? "std::string_view"
                                 : std::string(primitive_cpp(constant.type.base));
    out +=
        fmt::format("  static constexpr {} {} = {};\n", type, constant.name, constant.initializer);
  }
  if (!spec.constants.empty() && !spec.fields.empty()) out += "\n";
  for (const Field& field : spec.fields) {
    write_comments(out, field.comments, "  ");
    out += fmt::format("  {} {}{};\n", field_cpp(field.type), field.name,
                       field.default_initializer ? " = " + *field.default_initializer : "{}");
  }
  out += "};\n";
}

// `text` as C++ string literals, one per line of it, each on a line of its
// own after `indent`; every byte that is not printable ASCII as an octal
// escape, so the header is ASCII whatever the .msg file's encoding.
std::string string_literal(std::string_view text, std::string_view indent) {
  if (text.empty()) return "\"\"";
  std::string out;
  bool line_open = false;
  for (const char c : text) {
    if (!line_open) {
      if (!out.empty()) out += fmt::format("\n{}", indent);
      out += '"';
      line_open = true;
    }
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n\"";
      line_open = false;
    } else if (c == '"' || c == '\\' || c == '?') {  // '?': no trigraph, whatever the mode
      out += '\\';
      out += c;
    } else if (c == '\t') {
      out += "\\t";
    } else if (byte < 0x20 || byte >= 0x7f) {
      out += fmt::format("\\{:03o}", byte);
    } else {
      out += c;
    }
  }
  if (line_open) out += '"';
  return out;
}

void write_traits(std::string& out, const MessageSpec& spec) {
  out += fmt::format(
      "template <>\n"
      "struct agnocast::message_traits<{0}> {{\n"
      "  using Message = {0};\n"
      "  static constexpr bool is_declared = true;\n"
      "  static constexpr std::string_view type_name = \"{1}/{2}/{3}\";\n"
      "  static constexpr std::array fields{{\n",
      full_name(spec), spec.package, spec.kind, spec.name);
  for (const Field& field : spec.fields) {
    std::string bounds;
    if (field.type.container == Container::Sequence && field.type.length != 0) {
      bounds += fmt::format(".sequence_bound = {}", field.type.length);
    }
    if (field.type.string_bound != 0) {
      bounds +=
          fmt::format("{}.string_bound = {}", bounds.empty() ? "" : ", ", field.type.string_bound);
    }
    out += fmt::format(
        "      agnocast::describe_field<decltype(Message::{0})>(\"{0}\", offsetof(Message, "
        "{0}){1}),\n",
        field.name, bounds.empty() ? "" : ", {" + bounds + "}");
  }
  out += fmt::format(
      "  }};\n"
      "  static constexpr std::string_view definition =\n"
      "      {};\n"
      "  static constexpr agnocast::TypeDescriptor descriptor =\n"
      "      agnocast::describe_type<Message>(type_name, fields, definition);\n"
      "  static constexpr std::uint64_t type_hash = descriptor.hash;\n"
      "}};\n",
      string_literal(spec.text, "      "));
}

void write_bound_checks(std::string& out, const MessageSpec& spec, const Field& field) {
  const std::string where =
      fmt::format("{}/{}/{}.{}", spec.package, spec.kind, spec.name, field.name);
  if (field.type.container == Container::Sequence && field.type.length != 0) {
    out += fmt::format("  agnocast::cdr::check_bound(message.{}.size(), {}, \"{}\");\n", field.name,
                       field.type.length, where);
  }
  if (field.type.string_bound == 0) return;
  if (field.type.container == Container::None) {
    out += fmt::format("  agnocast::cdr::check_bound(message.{}.size(), {}, \"{}\");\n", field.name,
                       field.type.string_bound, where);
  } else {
    out += fmt::format(
        "  for (const auto& element : message.{}) {{\n"
        "    agnocast::cdr::check_bound(element.size(), {}, \"{}\");\n"
        "  }}\n",
        field.name, field.type.string_bound, where);
  }
}

void write_cdr(std::string& out, const MessageSpec& spec) {
  out += fmt::format("inline void cdr_write(agnocast::cdr::Writer& writer, const {}& message) {{\n",
                     spec.name);
  for (const Field& field : spec.fields) write_bound_checks(out, spec, field);
  for (const Field& field : spec.fields) {
    out += fmt::format("  writer.write(message.{});\n", field.name);
  }
  out += "}\n\n";
  out += fmt::format("inline void cdr_read(agnocast::cdr::Reader& reader, {}& message) {{\n",
                     spec.name);
  for (const Field& field : spec.fields) {
    out += fmt::format("  reader.read(message.{});\n", field.name);
  }
  for (const Field& field : spec.fields) write_bound_checks(out, spec, field);
  out += "}\n";
}

// The head of a header generated from `source`: the library's headers it
// needs, then those of the messages the parts' fields use.
std::string preamble(const std::string& source, std::initializer_list<std::string_view> library,
                     std::initializer_list<const MessageSpec*> parts) {
  std::string out = fmt::format(
      "// Generated by agnocast-msggen from {}; do not edit.\n"
      "#pragma once\n\n",
      source);
  for (const std::string_view header : library) out += fmt::format("#include <{}>\n", header);
  std::set<std::string> includes;
  for (const MessageSpec* part : parts) {
    for (const Field& field : part->fields) {
      if (field.type.base == BaseType::Message) {
        includes.insert(header_path(field.type.package, field.type.name));
      }
    }
  }
  if (!includes.empty()) out += "\n";
  for (const std::string& include : includes) out += fmt::format("#include <{}>\n", include);
  return out;
}

}  // namespace

std::string snake_case(std::string_view type_name) {
  std::string out;
  for (std::size_t i = 0; i < type_name.size(); ++i) {
    const auto c = static_cast<unsigned char>(type_name[i]);
    if (std::isupper(c) && i > 0) {
      const auto before = static_cast<unsigned char>(type_name[i - 1]);
      const bool word_starts = std::islower(before) || std::isdigit(before);
      // The last capital of an acronym starts the next word: TFMessage -> tf_message.
      const bool acronym_ends = std::isupper(before) && i + 1 < type_name.size() &&
                                std::islower(static_cast<unsigned char>(type_name[i + 1]));
      if (word_starts || acronym_ends) out += '_';
    }
    out += static_cast<char>(std::tolower(c));
  }
  return out;
}

std::string header_path(const std::string& package, const std::string& name) {
  return fmt::format("{}/msg/{}.hpp", package, snake_case(name));
}

std::string service_header_path(const std::string& package, const std::string& name) {
  return fmt::format("{}/srv/{}.hpp", package, snake_case(name));
}

std::string write_header(const MessageSpec& spec) {
  std::string out = preamble(fmt::format("{}/msg/{}.msg", spec.package, spec.name),
                             {"agnocast/message.hpp"}, {&spec});
  out += fmt::format("\nnamespace {}::msg {{\n\n", spec.package);
  write_struct(out, spec);
  out += fmt::format("\n}}  // namespace {}::msg\n\n", spec.package);
  write_traits(out, spec);
  out += fmt::format("\nnamespace {}::msg {{\n\n", spec.package);
  write_cdr(out, spec);
  out += fmt::format("\n}}  // namespace {}::msg\n", spec.package);
  return out;
}

std::string write_service_header(const ServiceSpec& spec) {
  const MessageSpec& request = spec.request;
  const MessageSpec& response = spec.response;
  std::string out =
      preamble(fmt::format("{}/srv/{}.srv", spec.package, spec.name),
               {"agnocast/message.hpp", "agnocast/service_traits.hpp"}, {&request, &response});
  out += fmt::format("\nnamespace {}::srv {{\n\n", spec.package);
  write_struct(out, request);
  out += "\n";
  write_struct(out, response);
  out += fmt::format(
      "\n"
      "struct {0} {{\n"
      "  using Request = {1};\n"
      "  using Response = {2};\n"
      "}};\n",
      spec.name, request.name, response.name);
  out += fmt::format("\n}}  // namespace {}::srv\n\n", spec.package);
  write_traits(out, request);
  out += "\n";
  write_traits(out, response);
  out += fmt::format(
      "\n"
      "template <>\n"
      "struct agnocast::service_traits<{0}::srv::{1}> {{\n"
      "  static constexpr bool is_declared = true;\n"
      "  static constexpr std::string_view type_name = \"{0}/srv/{1}\";\n"
      "  static constexpr std::uint64_t request_type_hash =\n"
      "      agnocast::message_traits<{0}::srv::{2}>::type_hash;\n"
      "  static constexpr std::uint64_t response_type_hash =\n"
      "      agnocast::message_traits<{0}::srv::{3}>::type_hash;\n"
      "}};\n",
      spec.package, spec.name, request.name, response.name);
  out += fmt::format("\nnamespace {}::srv {{\n\n", spec.package);
  write_cdr(out, request);
  out += "\n";
  write_cdr(out, response);
  out += fmt::format("\n}}  // namespace {}::srv\n", spec.package);
  return out;
}

}  // namespace msggen
