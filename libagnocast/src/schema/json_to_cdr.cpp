#include "agnocast/json_to_cdr.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "agnocast/cdr.hpp"
#include "agnocast/limits.hpp"

namespace agnocast {
namespace {

using nlohmann::json;

// A message nests at most message_max_nesting deep, each level an object and
// perhaps an array around it: anything deeper is no message, and is refused
// while it is parsed, before it costs memory or stack.
constexpr int json_depth_max = 2 * static_cast<int>(message_max_nesting) + 2;

// What the user wrote, short enough for one line.
std::string shown(const json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

// Writes the message's CDR as the schema walks the JSON; fields missing from
// it are written as their zero value.
class JsonToCdr {
 public:
  JsonToCdr(const Schema& schema, const JsonToCdrOptions& options, std::vector<std::uint8_t>& out)
      : schema_(schema), options_(options), out_(out), writer_(out) {}

  void message(const SchemaType& type, const json* value) {
    if (value && !value->is_object()) {
      fail("takes an object of the fields of " + type.name + ", not " + shown(*value));
    }
    if (value) {
      for (const auto& [key, unused] : value->items()) {
        if (!has_field(type, key)) unknown_field(type, key);
      }
    }
    for (const SchemaField& field : type.fields) {
      const std::size_t restore = path_.size();
      if (!path_.empty()) path_ += '.';
      path_ += field.name;
      const json* given = nullptr;
      if (value) {
        const auto found = value->find(field.name);
        if (found != value->end()) given = &*found;
      }
      this->field(field, given);
      path_.resize(restore);
    }
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    const std::string where = path_.empty() ? std::string("the message") : "field '" + path_ + "'";
    throw JsonInputError(schema_.types[0].name + ": " + where + " " + problem);
  }

  static bool has_field(const SchemaType& type, std::string_view name) {
    for (const SchemaField& field : type.fields) {
      if (field.name == name) return true;
    }
    return false;
  }

  [[noreturn]] void unknown_field(const SchemaType& type, const std::string& key) const {
    std::string names;
    for (const SchemaField& field : type.fields) names += (names.empty() ? "" : ", ") + field.name;
    const std::string in = path_.empty() ? std::string() : " (in '" + path_ + "')";
    throw JsonInputError(schema_.types[0].name + ": unknown field " + shown(json(key)) + in +
                         " of " + type.name + "; its fields: " + (names.empty() ? "none" : names));
  }

  // Every element costs a visit: a type of empty messages in a long array
  // writes nothing, and must still end.
  void spend(std::size_t bytes, std::size_t visits) {
    if (out_.size() > options_.max_bytes || bytes > options_.max_bytes - out_.size() ||
        visits > options_.max_bytes - visits_) {
      fail("makes the message longer than " + std::to_string(options_.max_bytes) + " bytes");
    }
    visits_ += visits;
  }

  void field(const SchemaField& field, const json* value) {
    if (field.kind == FieldKind::Opaque) fail("holds opaque bytes, which have no CDR form");
    switch (field.shape) {
      case FieldShape::Single:
        element(field, value);
        return;
      case FieldShape::Array:
        if (value) {
          if (!value->is_array()) fail("takes an array, not " + shown(*value));
          if (value->size() != field.array_length) {
            fail("holds exactly " + std::to_string(field.array_length) + " elements, not " +
                 std::to_string(value->size()));
          }
        }
        elements(field, value, field.array_length);
        return;
      case FieldShape::Sequence: {
        if (value && !value->is_array()) fail("takes an array, not " + shown(*value));
        const std::size_t count = value ? value->size() : 0;
        if (field.sequence_bound != 0 && count > field.sequence_bound) {
          fail("holds at most " + std::to_string(field.sequence_bound) + " elements, not " +
               std::to_string(count));
        }
        if (count > std::numeric_limits<std::uint32_t>::max()) fail("is longer than CDR counts");
        writer_.write(static_cast<std::uint32_t>(count));
        elements(field, value, count);
        return;
      }
    }
  }

  void elements(const SchemaField& field, const json* values, std::size_t count) {
    const std::uint32_t size = primitive_size(field.kind);
    spend(static_cast<std::size_t>(size) * std::min<std::size_t>(count, options_.max_bytes), count);
    const std::size_t restore = path_.size();
    for (std::size_t i = 0; i < count; ++i) {
      path_ += '[' + std::to_string(i) + ']';
      element(field, values ? &(*values)[i] : nullptr);
      path_.resize(restore);
    }
  }

  void element(const SchemaField& field, const json* value) {
    switch (field.kind) {
      case FieldKind::Bool:
        if (value && !value->is_boolean()) fail("takes true or false, not " + shown(*value));
        writer_.write(static_cast<std::uint8_t>(value && value->get<bool>() ? 1 : 0));
        return;
      case FieldKind::Int8:
        return integer<std::int8_t>(field, value);
      case FieldKind::UInt8:
        return integer<std::uint8_t>(field, value);
      case FieldKind::Int16:
        return integer<std::int16_t>(field, value);
      case FieldKind::UInt16:
        return integer<std::uint16_t>(field, value);
      case FieldKind::Int32:
        return integer<std::int32_t>(field, value);
      case FieldKind::UInt32:
        return integer<std::uint32_t>(field, value);
      case FieldKind::Int64:
        return integer<std::int64_t>(field, value);
      case FieldKind::UInt64:
        return integer<std::uint64_t>(field, value);
      case FieldKind::Float32:
        return floating<float>(field, value);
      case FieldKind::Float64:
        return floating<double>(field, value);
      case FieldKind::String:
        return string(field, value);
      case FieldKind::Message:
        return message(schema_.types[field.nested], value);
      case FieldKind::Opaque:
        break;
    }
    fail("holds opaque bytes, which have no CDR form");
  }

  template <class T>
  void integer(const SchemaField& field, const json* value) {
    T number = 0;
    if (value) {
      bool fits = false;
      // JSON's integers read as uint64 when positive, int64 when negative.
      if (value->is_number_unsigned()) {
        const auto given = value->get<std::uint64_t>();
        fits = std::in_range<T>(given);
        number = static_cast<T>(given);
      } else if (value->is_number_integer()) {
        const auto given = value->get<std::int64_t>();
        fits = std::in_range<T>(given);
        number = static_cast<T>(given);
      } else {
        fail(std::string("takes an integer (") + primitive_name(field.kind) + "), not " +
             shown(*value));
      }
      if (!fits) {
        fail(shown(*value) + " does not fit " + primitive_name(field.kind) + " (" +
             std::to_string(std::numeric_limits<T>::min()) + " to " +
             std::to_string(std::numeric_limits<T>::max()) + ")");
      }
    }
    writer_.write(number);
  }

  template <class T>
  void floating(const SchemaField& field, const json* value) {
    T number = 0;
    if (value) {
      if (!value->is_number()) {
        fail(std::string("takes a number (") + primitive_name(field.kind) + "), not " +
             shown(*value));
      }
      // Rounded to the nearest T: what rounds to infinity does not fit (IEEE
      // types reach infinity, so the conversion itself is defined).
      const double given = value->get<double>();
      number = static_cast<T>(given);
      if (!std::isfinite(number))
        fail(shown(*value) + " does not fit " + primitive_name(field.kind));
    }
    writer_.write(number);
  }

  void string(const SchemaField& field, const json* value) {
    static const std::string empty;
    if (value && !value->is_string()) fail("takes a string, not " + shown(*value));
    const std::string& text = value ? value->get_ref<const std::string&>() : empty;
    if (field.string_bound != 0 && text.size() > field.string_bound) {
      fail("holds at most " + std::to_string(field.string_bound) + " bytes, not " +
           std::to_string(text.size()));
    }
    if (text.find('\0') != std::string::npos)
      fail("holds a NUL character, which CDR strings cannot");
    if (text.size() >= std::numeric_limits<std::uint32_t>::max()) fail("is longer than CDR counts");
    spend(text.size() + 8, 0);
    writer_.write(static_cast<std::uint32_t>(text.size() + 1));
    writer_.write_elements(text.data(), text.size());
    writer_.write('\0');
  }

  const Schema& schema_;
  const JsonToCdrOptions& options_;
  std::vector<std::uint8_t>& out_;
  cdr::Writer writer_;
  std::string path_;  // of the value being written, from the message: "cells[2].note"
  std::size_t visits_ = 0;
};

json parse(std::string_view text) {
  const auto limit_depth = [](int depth, json::parse_event_t event, json&) {
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= json_depth_max) {
      throw JsonInputError("the JSON nests deeper than any message (" +
                           std::to_string(json_depth_max) + " levels)");
    }
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), limit_depth);
  } catch (const json::exception& error) {
    throw JsonInputError(std::string("not JSON: ") + error.what());
  }
}

}  // namespace

std::vector<std::uint8_t> json_to_cdr(std::string_view text, const Schema& schema,
                                      const JsonToCdrOptions& options) {
  const SchemaType& root = schema.types.at(0);
  if (root.fields.empty()) {
    throw JsonInputError("type " + root.name + " describes no fields, so it has no CDR form");
  }
  const json value = parse(text);
  std::vector<std::uint8_t> out(cdr::encapsulation_header.begin(), cdr::encapsulation_header.end());
  JsonToCdr(schema, options, out).message(root, &value);
  return out;
}

std::string json_syntax_problem(std::string_view json) {
  try {
    parse(json);
  } catch (const JsonInputError& error) {
    return error.what();
  }
  return {};
}

}  // namespace agnocast
