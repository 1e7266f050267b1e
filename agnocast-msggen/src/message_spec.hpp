// What one .msg or .srv file says, after parsing and before resolving other messages.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace msggen {

// A mistake in an input file, located for the user: what() is "file:line: message".
class InputError : public std::runtime_error {
 public:
  // line 0: about the file as a whole.
  InputError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(located(file, line, message)) {}

 private:
  // Appended piece by piece: GCC 12 at -O3 warns falsely (-Wrestrict) on a chain of +.
  static std::string located(const std::string& file, int line, const std::string& message) {
    std::string text = file;
    if (line > 0) text.append(":").append(std::to_string(line));
    return text.append(": ").append(message);
  }
};

enum class BaseType {
  Bool,
  Byte,
  Char,
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Int64,
  UInt64,
  Float32,
  Float64,
  String,
  Message,
};

enum class Container { None, FixedArray, Sequence };

struct FieldType {
  BaseType base = BaseType::Int32;
  std::string package;             // Message only: the package, filled in for same-package types
  std::string name;                // Message only
  std::uint32_t string_bound = 0;  // String only: string<=N, 0 when unbounded
  Container container = Container::None;
  std::uint32_t length = 0;  // FixedArray: N; Sequence: the bound of T[<=N], 0 when unbounded
};

struct Field {
  FieldType type;
  std::string name;
  std::optional<std::string> default_initializer;  // a C++ expression for the value
  std::vector<std::string> comments;
  int line = 0;
};

struct Constant {
  FieldType type;
  std::string name;
  std::string initializer;  // a C++ expression for the value
  std::vector<std::string> comments;
  int line = 0;
};

struct MessageSpec {
  std::string package;
  std::string name;
  // "msg", or "srv" for a service's request and response: the namespace
  // package::kind, the type name "package/kind/name" and the header's folder.
  std::string kind = "msg";
  std::string file;
  std::string text;  // the file (a service's: its part) as read, for bags and tools
  std::vector<std::string> comments;  // the block before the first member
  std::vector<Constant> constants;
  std::vector<Field> fields;
};

// A .srv file: two messages, Name_Request and Name_Response, of kind "srv".
struct ServiceSpec {
  std::string package;
  std::string name;
  std::string file;
  MessageSpec request;
  MessageSpec response;
};

bool is_primitive(BaseType type);

}  // namespace msggen
