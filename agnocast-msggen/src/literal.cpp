#include "literal.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace msggen {
namespace {

struct IntegerRange {
  std::int64_t min;
  std::uint64_t max;
  std::string_view suffix;  // keeps 64-bit literals from being narrowed
};

IntegerRange range_of(BaseType base) {
  switch (base) {
    case BaseType::Byte:
    case BaseType::Char:
    case BaseType::UInt8:
      return {0, 255, ""};
    case BaseType::Int8:
      return {-128, 127, ""};
    case BaseType::Int16:
      return {-32768, 32767, ""};
    case BaseType::UInt16:
      return {0, 65535, ""};
    case BaseType::Int32:
      return {std::numeric_limits<std::int32_t>::min(), 2147483647, ""};
    case BaseType::UInt32:
      return {0, 4294967295u, "u"};
    case BaseType::Int64:
      return {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max(),
              "LL"};
    default:
      return {0, std::numeric_limits<std::uint64_t>::max(), "ULL"};
  }
}

std::string integer_value(BaseType base, std::string_view text) {
  const IntegerRange range = range_of(base);
  const bool negative = !text.empty() && text.front() == '-';
  std::string_view digits = negative ? text.substr(1) : text;
  std::uint64_t magnitude = 0;
  const auto [end, error] =
      std::from_chars(digits.data(), digits.data() + digits.size(), magnitude);
  if (digits.empty() || error != std::errc{} || end != digits.data() + digits.size()) {
    throw std::invalid_argument(fmt::format("'{}' is not an integer", text));
  }
  const std::uint64_t min_magnitude = range.min < 0 ? 0 - static_cast<std::uint64_t>(range.min) : 0;
  if ((negative && magnitude > min_magnitude) || (!negative && magnitude > range.max)) {
    throw std::invalid_argument(
        fmt::format("{} is out of range [{}, {}]", text, range.min, range.max));
  }
  if (negative && magnitude == 0) return "0";
  if (negative && magnitude == min_magnitude && range.suffix == "LL") {
    return "(-9223372036854775807LL - 1)";  // the literal 9223372036854775808 does not exist
  }
  return fmt::format("{}{}{}", negative ? "-" : "", magnitude, range.suffix);
}

std::string float_value(BaseType base, std::string_view text) {
  const std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size() || !std::isfinite(value)) {
    throw std::invalid_argument(fmt::format("'{}' is not a finite number", text));
  }
  std::string printed;
  if (base == BaseType::Float32) {
    if (std::abs(value) > std::numeric_limits<float>::max()) {
      throw std::invalid_argument(fmt::format("{} is out of range of float32", text));
    }
    printed = fmt::format("{}", static_cast<float>(value));
  } else {
    printed = fmt::format("{}", value);
  }
  if (printed.find_first_of(".e") == std::string::npos) printed += ".0";
  return base == BaseType::Float32 ? printed + "F" : printed;
}

std::string bool_value(std::string_view text) {
  if (text == "true" || text == "True" || text == "1") return "true";
  if (text == "false" || text == "False" || text == "0") return "false";
  throw std::invalid_argument(fmt::format("'{}' is not a bool (true, false, 1, 0)", text));
}

// Quoted with ' or " (escapes \\ \' \" \n \t), or else the text as it stands.
std::string string_content(std::string_view text) {
  if (text.size() < 2 || (text.front() != '"' && text.front() != '\'') ||
      text.back() != text.front()) {
    return std::string(text);
  }
  std::string content;
  for (std::size_t i = 1; i + 1 < text.size(); ++i) {
    char c = text[i];
    if (c == '\\' && i + 2 < text.size()) {
      c = text[++i];
      if (c == 'n') c = '\n';
      if (c == 't') c = '\t';
    }
    content += c;
  }
  return content;
}

std::string scalar_value(const FieldType& type, std::string_view text) {
  text = trim(text);
  switch (type.base) {
    case BaseType::Bool:
      return bool_value(text);
    case BaseType::Float32:
    case BaseType::Float64:
      return float_value(type.base, text);
    case BaseType::String: {
      const std::string content = string_content(text);
      if (type.string_bound != 0 && content.size() > type.string_bound) {
        throw std::invalid_argument(
            fmt::format("the string has {} characters, more than its bound {}", content.size(),
                        type.string_bound));
      }
      return cpp_string_literal(content);
    }
    case BaseType::Message:
      throw std::invalid_argument("a message field cannot have a default value");
    default:
      return integer_value(type.base, text);
  }
}

// Splits "[a, 'b,c', d]" at the commas outside quotes.
std::vector<std::string_view> array_elements(std::string_view text) {
  text = trim(text);
  if (text.size() < 2 || text.front() != '[' || text.back() != ']') {
    throw std::invalid_argument(fmt::format("'{}' is not an array value like [1, 2]", text));
  }
  text = trim(text.substr(1, text.size() - 2));
  std::vector<std::string_view> elements;
  if (text.empty()) return elements;
  char quote = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote != 0) {
      if (c == '\\')
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == ',') {
      elements.push_back(trim(text.substr(start, i - start)));
      start = i + 1;
    }
  }
  elements.push_back(trim(text.substr(start)));
  return elements;
}

}  // namespace

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

std::string cpp_string_literal(std::string_view text) {
  std::string literal = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        literal += "\\\"";
        break;
      case '\\':
        literal += "\\\\";
        break;
      case '\n':
        literal += "\\n";
        break;
      case '\t':
        literal += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          literal += fmt::format("\\{:03o}", static_cast<unsigned char>(c));
        } else {
          literal += c;
        }
    }
  }
  return literal + "\"";
}

std::string cpp_value(const FieldType& type, std::string_view text) {
  if (type.container == Container::None) return scalar_value(type, text);
  const std::vector<std::string_view> elements = array_elements(text);
  if (type.container == Container::FixedArray && elements.size() != type.length) {
    throw std::invalid_argument(
        fmt::format("the array has {} elements, its type needs {}", elements.size(), type.length));
  }
  if (type.container == Container::Sequence && type.length != 0 && elements.size() > type.length) {
    throw std::invalid_argument(fmt::format("the array has {} elements, more than its bound {}",
                                            elements.size(), type.length));
  }
  FieldType element = type;
  element.container = Container::None;
  std::string expression = "{";
  for (std::size_t i = 0; i < elements.size(); ++i) {
    expression += (i == 0 ? "" : ", ") + scalar_value(element, elements[i]);
  }
  return expression + "}";
}

}  // namespace msggen
