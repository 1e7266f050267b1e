#include "msg_parser.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <map>
#include <set>
#include <stdexcept>

#include "literal.hpp"

namespace msggen {
namespace {

const std::map<std::string_view, BaseType>& primitive_names() {
  static const std::map<std::string_view, BaseType> names{
      {"bool", BaseType::Bool},       {"byte", BaseType::Byte},     {"char", BaseType::Char},
      {"int8", BaseType::Int8},       {"uint8", BaseType::UInt8},   {"int16", BaseType::Int16},
      {"uint16", BaseType::UInt16},   {"int32", BaseType::Int32},   {"uint32", BaseType::UInt32},
      {"int64", BaseType::Int64},     {"uint64", BaseType::UInt64}, {"float32", BaseType::Float32},
      {"float64", BaseType::Float64}, {"string", BaseType::String},
  };
  return names;
}

bool is_lower_identifier(std::string_view name) {
  if (name.empty() || !std::islower(static_cast<unsigned char>(name.front()))) return false;
  for (const char c : name) {
    if (!std::islower(static_cast<unsigned char>(c)) &&
        !std::isdigit(static_cast<unsigned char>(c)) && c != '_') {
      return false;
    }
  }
  return name.back() != '_' && name.find("__") == std::string_view::npos;
}

bool is_cpp_keyword(std::string_view name) {
  static const std::set<std::string_view> keywords{
      "alignas",   "alignof",   "and",       "asm",       "auto",     "bool",     "break",
      "case",      "catch",     "char",      "class",     "concept",  "const",    "consteval",
      "constexpr", "constinit", "continue",  "decltype",  "default",  "delete",   "do",
      "double",    "else",      "enum",      "explicit",  "export",   "extern",   "false",
      "float",     "for",       "friend",    "goto",      "if",       "inline",   "int",
      "long",      "mutable",   "namespace", "new",       "noexcept", "not",      "nullptr",
      "operator",  "or",        "private",   "protected", "public",   "register", "requires",
      "return",    "short",     "signed",    "sizeof",    "static",   "struct",   "switch",
      "template",  "this",      "throw",     "true",      "try",      "typedef",  "typeid",
      "typename",  "union",     "unsigned",  "using",     "virtual",  "void",     "volatile",
      "while",     "xor"};
  return keywords.contains(name);
}

bool is_constant_name(std::string_view name) {
  if (name.empty() || !std::isupper(static_cast<unsigned char>(name.front()))) return false;
  for (const char c : name) {
    if (!std::isupper(static_cast<unsigned char>(c)) &&
        !std::isdigit(static_cast<unsigned char>(c)) && c != '_') {
      return false;
    }
  }
  return name.back() != '_' && name.find("__") == std::string_view::npos;
}

bool is_type_name(std::string_view name) {
  if (name.empty() || !std::isupper(static_cast<unsigned char>(name.front()))) return false;
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

// A positive bound or length, as in string<=N, T[N], T[<=N].
std::uint32_t parse_count(std::string_view text, std::string_view what) {
  std::uint32_t count = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), count);
  if (text.empty() || error != std::errc{} || end != text.data() + text.size() || count == 0) {
    throw std::invalid_argument(
        fmt::format("bad {} '{}': expected a positive integer below 2^32", what, text));
  }
  return count;
}

FieldType parse_type(std::string_view text, const std::string& package) {
  FieldType type;
  if (const std::size_t open = text.find('['); open != std::string_view::npos) {
    if (text.back() != ']') throw std::invalid_argument(fmt::format("bad array type '{}'", text));
    const std::string_view inside = text.substr(open + 1, text.size() - open - 2);
    if (inside.empty()) {
      type.container = Container::Sequence;
    } else if (inside.starts_with("<=")) {
      type.container = Container::Sequence;
      type.length = parse_count(inside.substr(2), "array bound");
    } else {
      type.container = Container::FixedArray;
      type.length = parse_count(inside, "array length");
    }
    text = text.substr(0, open);
  }
  if (text.starts_with("string<=")) {
    type.base = BaseType::String;
    type.string_bound = parse_count(text.substr(8), "string bound");
    return type;
  }
  if (const auto primitive = primitive_names().find(text); primitive != primitive_names().end()) {
    type.base = primitive->second;
    return type;
  }
  type.base = BaseType::Message;
  if (const std::size_t slash = text.find('/'); slash != std::string_view::npos) {
    type.package = std::string(text.substr(0, slash));
    type.name = std::string(text.substr(slash + 1));
    if (!is_lower_identifier(type.package)) {
      throw std::invalid_argument(fmt::format("bad package name in type '{}'", text));
    }
  } else if (text == "Header") {
    type.package = "std_msgs";  // ROS 2 keeps ROS 1's shorthand for std_msgs/Header
    type.name = "Header";
  } else {
    type.package = package;
    type.name = std::string(text);
  }
  if (!is_type_name(type.name)) {
    throw std::invalid_argument(fmt::format(
        "unknown type '{}': not a primitive type, and not a message name (CamelCase)", text));
  }
  return type;
}

// Cuts the comment off a line; '#' inside a quoted string is text.
std::string_view split_comment(std::string_view line, std::string_view& comment) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote != 0) {
      if (c == '\\')
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      comment = trim(line.substr(i + 1));
      return line.substr(0, i);
    }
  }
  comment = {};
  return line;
}

// The line between a service's request and its response.
bool is_separator(std::string_view line) {
  std::string_view comment;
  return trim(split_comment(line, comment)) == "---";
}

class Parser {
 public:
  Parser(const std::string& file, const std::string& package, const std::string& name,
         const std::string& kind) {
    spec_.file = file;
    spec_.package = package;
    spec_.name = name;
    spec_.kind = kind;
  }

  // `text` starts at line `first_line` of the file.
  MessageSpec run(std::string_view text, int first_line) {
    spec_.text = std::string(text);
    int line_number = first_line - 1;
    while (!text.empty()) {
      const std::size_t end = text.find('\n');
      std::string_view line = text.substr(0, end);
      text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
      ++line_number;
      try {
        parse_line(line, line_number);
      } catch (const std::invalid_argument& error) {
        throw InputError(spec_.file, line_number, error.what());
      }
    }
    if (!seen_member_) spec_.comments = std::move(pending_comments_);
    if (spec_.fields.empty()) {
      // As in ROS 2: a C++ struct and a CDR encoding need at least one member.
      FieldType byte;
      byte.base = BaseType::UInt8;
      spec_.fields.push_back(
          Field{byte, "structure_needs_at_least_one_member", std::nullopt, {}, 0});
    }
    return std::move(spec_);
  }

 private:
  void parse_line(std::string_view line, int line_number) {
    std::string_view comment;
    const std::string_view code = trim(split_comment(line, comment));
    if (code.empty()) {
      if (line.find('#') != std::string_view::npos) {
        pending_comments_.emplace_back(comment);
        return;
      }
      // A blank line detaches comments from the next member; the first such block
      // describes the message itself.
      if (!seen_member_ && spec_.comments.empty()) spec_.comments = std::move(pending_comments_);
      pending_comments_.clear();
      return;
    }
    if (code == "---") {
      throw std::invalid_argument(
          "'---' separates a service or action, not allowed in a .msg file");
    }
    const std::size_t space = code.find_first_of(" \t");
    if (space == std::string_view::npos) {
      throw std::invalid_argument(fmt::format("expected 'type name', got '{}'", code));
    }
    const std::string_view type_text = code.substr(0, space);
    const std::string_view rest = trim(code.substr(space));
    const FieldType type = parse_type(type_text, spec_.package);
    std::vector<std::string> comments = std::move(pending_comments_);
    pending_comments_.clear();
    seen_member_ = true;

    const std::size_t equals = rest.find('=');
    // A string constant's value runs to the end of the line, '#' included.
    const bool comment_is_value = equals != std::string_view::npos && type.base == BaseType::String;
    if (!comment.empty() && !comment_is_value) comments.emplace_back(comment);
    if (equals != std::string_view::npos) {
      // The value starts after the '=' that follows the name: a bounded string
      // type (string<=N) has one of its own. rest is a view into line.
      const auto value_at = static_cast<std::size_t>(rest.data() - line.data()) + equals + 1;
      add_constant(type, trim(rest.substr(0, equals)), line.substr(value_at), comment,
                   std::move(comments), line_number);
      return;
    }
    const std::size_t name_end = rest.find_first_of(" \t");
    const std::string_view name = rest.substr(0, name_end);
    const std::string_view default_text =
        name_end == std::string_view::npos ? std::string_view{} : trim(rest.substr(name_end));
    add_field(type, name, default_text, std::move(comments), line_number);
  }

  void add_constant(const FieldType& type, std::string_view name, std::string_view value_text,
                    std::string_view comment, std::vector<std::string> comments, int line_number) {
    if (!is_constant_name(name)) {
      throw std::invalid_argument(fmt::format(
          "bad constant name '{}': upper case letters, digits and single underscores", name));
    }
    if (type.container != Container::None || type.base == BaseType::Message) {
      throw std::invalid_argument("a constant must have a primitive or string type");
    }
    claim_name(name);
    std::string_view value = trim(value_text);
    if (type.base != BaseType::String && !comment.empty())
      value = trim(value.substr(0, value.find('#')));
    spec_.constants.push_back(Constant{type, std::string(name), cpp_value(type, value),
                                       std::move(comments), line_number});
  }

  void add_field(const FieldType& type, std::string_view name, std::string_view default_text,
                 std::vector<std::string> comments, int line_number) {
    if (!is_lower_identifier(name)) {
      throw std::invalid_argument(fmt::format(
          "bad field name '{}': lower case letters, digits and single underscores, starting "
          "with a letter",
          name));
    }
    if (is_cpp_keyword(name)) {
      throw std::invalid_argument(fmt::format("field name '{}' is a C++ keyword", name));
    }
    claim_name(name);
    Field field{type, std::string(name), std::nullopt, std::move(comments), line_number};
    if (!default_text.empty()) field.default_initializer = cpp_value(type, default_text);
    spec_.fields.push_back(std::move(field));
  }

  void claim_name(std::string_view name) {
    if (!names_.insert(std::string(name)).second) {
      throw std::invalid_argument(fmt::format("duplicate field or constant '{}'", name));
    }
  }

  MessageSpec spec_;
  std::vector<std::string> pending_comments_;
  std::set<std::string> names_;
  bool seen_member_ = false;
};

void check_package_name(const std::string& file, const std::string& package) {
  if (!is_lower_identifier(package)) {
    throw InputError(file, 0,
                     fmt::format("bad package name '{}': lower case letters, digits and "
                                 "single underscores",
                                 package));
  }
}

void check_type_name(const std::string& file, const std::string& name, std::string_view what) {
  if (!is_type_name(name)) {
    throw InputError(file, 0,
                     fmt::format("bad {} name '{}': CamelCase letters and digits", what, name));
  }
}

}  // namespace

bool is_primitive(BaseType type) { return type != BaseType::String && type != BaseType::Message; }

MessageSpec parse_message(std::string_view text, const std::string& file,
                          const std::string& package, const std::string& name) {
  check_package_name(file, package);
  check_type_name(file, name, "message");
  return Parser(file, package, name, "msg").run(text, 1);
}

ServiceSpec parse_service(std::string_view text, const std::string& file,
                          const std::string& package, const std::string& name) {
  check_package_name(file, package);
  check_type_name(file, name, "service");
  // Where the separator line starts and where the line after it starts.
  std::size_t separator = std::string_view::npos;
  std::size_t response_start = 0;
  int separator_line = 0;
  int line_number = 0;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = text.find('\n', start);
    const std::size_t next = end == std::string_view::npos ? text.size() : end + 1;
    ++line_number;
    if (is_separator(text.substr(start, next - start))) {
      if (separator != std::string_view::npos) {
        throw InputError(file, line_number,
                         fmt::format("a second '---' (the first is on line {}): a service has "
                                     "one request and one response",
                                     separator_line));
      }
      separator = start;
      response_start = next;
      separator_line = line_number;
    }
    start = next;
  }
  if (separator == std::string_view::npos) {
    throw InputError(file, 0,
                     "no line '---': a service is a request, a line '---', then a response");
  }
  ServiceSpec spec;
  spec.package = package;
  spec.name = name;
  spec.file = file;
  spec.request = Parser(file, package, name + "_Request", "srv").run(text.substr(0, separator), 1);
  spec.response = Parser(file, package, name + "_Response", "srv")
                      .run(text.substr(response_start), separator_line + 1);
  return spec;
}

}  // namespace msggen
