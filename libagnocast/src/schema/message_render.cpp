#include "agnocast/message_render.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "agnocast/schema_walk.hpp"

namespace agnocast {
namespace {

template <class T>
T load(const std::byte* at) {
  return load_unaligned<T>(at);
}

void append_quoted(std::string& out, std::string_view text) {
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          static constexpr char hex[] = "0123456789abcdef";
          out += "\\u00";
          out += hex[(c >> 4) & 0xF];
          out += hex[c & 0xF];
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

template <class Float>
void append_float(std::string& out, Float value, bool json) {
  if (!std::isfinite(value)) {
    out += json ? "null" : (std::isnan(value) ? ".nan" : (value > 0 ? ".inf" : "-.inf"));
    return;
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

// Renders one message as SchemaWalk visits it; text and JSON share how
// values are read and checked.
class Renderer {
 public:
  Renderer(const Schema& schema, const RenderOptions& options)
      : schema_(schema),
        options_(options),
        memory_(options.readable ? ForeignMemory(*options.readable) : ForeignMemory()) {}

  std::string text(const void* message) {
    json_ = false;
    const SchemaType& root = schema_.types[0];
    if (const char* problem = message_problem(root, message, memory_)) {
      marker(problem);
      out_ += '\n';
    } else if (root.fields.empty()) {
      out_ += "bytes: ";  // a raw type: its bytes are all there is to show
      append_bytes(static_cast<const std::byte*>(message), root.size);
      out_ += '\n';
    } else {
      SchemaWalk<Renderer>(schema_, memory_, *this)
          .message(root, static_cast<const std::byte*>(message));
    }
    return std::move(out_);
  }

  std::string json(const void* message) {
    json_ = true;
    const SchemaType& root = schema_.types[0];
    if (const char* problem = message_problem(root, message, memory_)) {
      marker(problem);
    } else if (root.fields.empty()) {
      out_ += "{\"bytes\":";
      append_bytes(static_cast<const std::byte*>(message), root.size);
      out_ += '}';
    } else {
      SchemaWalk<Renderer>(schema_, memory_, *this)
          .message(root, static_cast<const std::byte*>(message));
    }
    return std::move(out_);
  }

  // SchemaWalk's visitor.
  void begin_message(const SchemaType&) {
    levels_.push_back({next_indent_, std::move(next_prefix_), true});
    next_prefix_.clear();
    if (json_) out_ += '{';
  }
  void end_message(const SchemaType&) {
    levels_.pop_back();
    if (json_) out_ += '}';
  }

  void begin_field(const SchemaField& field) {
    Level& level = levels_.back();
    if (json_) {
      if (!level.first) out_ += ',';
      append_quoted(out_, field.name);
      out_ += ':';
    } else {
      // A list item's first line starts with its "- " instead of the indentation.
      out_ += !level.prefix.empty() ? level.prefix : std::string(level.indent, ' ');
      level.prefix.clear();
      out_ += field.name;
      out_ += ':';
      if (field.shape == FieldShape::Single) {
        if (field.kind == FieldKind::Message) {
          out_ += '\n';
          next_indent_ = level.indent + 2;
        } else {
          out_ += ' ';
        }
      }
    }
    level.first = false;
  }
  void end_field(const SchemaField& field) {
    if (!json_ && field.shape == FieldShape::Single && field.kind != FieldKind::Message) {
      out_ += '\n';
    }
  }

  void scalar(const SchemaField& field, const std::byte* at) { number(field.kind, at); }
  void numbers(const SchemaField& field, const std::byte* first, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      if (i > 0) out_ += json_ ? "," : ", ";
      number(field.kind, first + i * field.element_size);
    }
  }
  void opaque(const SchemaField& field, const std::byte* first, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      if (i > 0) out_ += json_ ? "," : ", ";
      append_bytes(first + i * field.element_size, field.element_size);
    }
  }
  void text(const SchemaField&, const ForeignText& found) {
    if (found.problem) {
      marker(found.problem);
    } else if (!spend(found.text.size())) {
      marker("too many values to show");
    } else {
      append_quoted(out_, found.text);
    }
  }

  bool begin_elements(const SchemaField& field, const ForeignElements& found) {
    const char* problem = found.problem;
    if (!problem && options_.show_arrays && !spend(found.count)) {
      problem = "too many values to show";
    }
    if (problem) {
      if (!json_) out_ += ' ';
      marker(problem);
      if (!json_) out_ += '\n';
      return false;
    }
    if (!options_.show_arrays) {
      out_ += json_ ? "{\"length\":" + std::to_string(found.count) + "}"
                    : " <" + std::to_string(found.count) + " elements>\n";
      return false;
    }
    const bool items = !json_ && field.kind == FieldKind::Message && found.count > 0;
    lists_.push_back(items);
    out_ += json_ ? "[" : (items ? "\n" : " [");
    return true;
  }
  void begin_element(const SchemaField& field, std::size_t index) {
    if (lists_.back()) {
      const std::size_t indent = levels_.back().indent;
      next_indent_ = indent + 4;
      next_prefix_ = std::string(indent + 2, ' ') + "- ";
    } else if (index > 0) {
      out_ += json_ ? "," : ", ";
    }
    (void)field;
  }
  void end_elements(const SchemaField&) {
    if (!lists_.back()) out_ += json_ ? "]" : "]\n";
    lists_.pop_back();
  }

 private:
  struct Level {
    std::size_t indent = 0;
    std::string prefix;  // text: replaces the first field's indentation
    bool first = true;   // JSON: no comma before the first field
  };

  // Takes `count` from the budget of values a checked message may show.
  bool spend(std::size_t count) {
    if (!memory_.checked()) return true;
    if (count > budget_) return false;
    budget_ -= count;
    return true;
  }

  void marker(const char* problem) {
    if (json_) {
      out_ += "{\"invalid\":";
      append_quoted(out_, problem);
      out_ += '}';
    } else {
      out_ += "<invalid: ";
      out_ += problem;
      out_ += '>';
    }
  }

  void append_bytes(const std::byte* at, std::size_t size) {
    static constexpr char hex[] = "0123456789abcdef";
    out_ += '"';
    for (std::size_t i = 0; i < size; ++i) {
      const auto byte = static_cast<unsigned>(at[i]);
      out_ += hex[byte >> 4];
      out_ += hex[byte & 0xF];
    }
    out_ += '"';
  }

  void number(FieldKind kind, const std::byte* at) {
    switch (kind) {
      case FieldKind::Bool:
        out_ += load<std::uint8_t>(at) != 0 ? "true" : "false";
        break;
      case FieldKind::Int8:
        out_ += std::to_string(load<std::int8_t>(at));
        break;
      case FieldKind::UInt8:
        out_ += std::to_string(load<std::uint8_t>(at));
        break;
      case FieldKind::Int16:
        out_ += std::to_string(load<std::int16_t>(at));
        break;
      case FieldKind::UInt16:
        out_ += std::to_string(load<std::uint16_t>(at));
        break;
      case FieldKind::Int32:
        out_ += std::to_string(load<std::int32_t>(at));
        break;
      case FieldKind::UInt32:
        out_ += std::to_string(load<std::uint32_t>(at));
        break;
      case FieldKind::Int64:
        out_ += std::to_string(load<std::int64_t>(at));
        break;
      case FieldKind::UInt64:
        out_ += std::to_string(load<std::uint64_t>(at));
        break;
      case FieldKind::Float32:
        append_float(out_, load<float>(at), json_);
        break;
      case FieldKind::Float64:
        append_float(out_, load<double>(at), json_);
        break;
      default:
        break;  // strings, messages and opaque bytes have their own visits
    }
  }

  const Schema& schema_;
  const RenderOptions& options_;
  const ForeignMemory memory_;
  std::size_t budget_ = options_.max_values;
  bool json_ = false;
  std::vector<Level> levels_;
  std::vector<bool> lists_;  // per open array: text shows its elements as "- " items
  std::size_t next_indent_ = 0;
  std::string next_prefix_;
  std::string out_;
};

}  // namespace

std::string render_message_text(const void* message, const Schema& schema,
                                const RenderOptions& options) {
  return Renderer(schema, options).text(message);
}

std::string render_message_json(const void* message, const Schema& schema,
                                const RenderOptions& options) {
  return Renderer(schema, options).json(message);
}

}  // namespace agnocast
