#include "agnocast/message_render.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace agnocast {
namespace {

template <class T>
T load(const std::byte* at) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return value;
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

// Walks one message in place; text and JSON share how values are read.
class Renderer {
 public:
  Renderer(const Schema& schema, const RenderOptions& options)
      : schema_(schema), options_(options) {}

  std::string text(const void* message) {
    json_ = false;
    const SchemaType& root = schema_.types[0];
    if (const char* problem = root_problem(message, root)) {
      marker(problem);
      out_ += '\n';
    } else if (root.fields.empty()) {
      out_ += "bytes: ";  // a raw type: its bytes are all there is to show
      append_bytes(static_cast<const std::byte*>(message), root.size);
      out_ += '\n';
    } else {
      text_message(root, static_cast<const std::byte*>(message), 0, "");
    }
    return std::move(out_);
  }

  std::string json(const void* message) {
    json_ = true;
    const SchemaType& root = schema_.types[0];
    if (const char* problem = root_problem(message, root)) {
      marker(problem);
    } else if (root.fields.empty()) {
      out_ += "{\"bytes\":";
      append_bytes(static_cast<const std::byte*>(message), root.size);
      out_ += '}';
    } else {
      json_message(root, static_cast<const std::byte*>(message));
    }
    return std::move(out_);
  }

 private:
  struct Elements {
    const std::byte* first = nullptr;
    std::size_t count = 0;
    const char* problem = nullptr;  // set: render this instead of the elements
  };

  bool checked() const { return options_.readable.has_value(); }

  // Whether `bytes` bytes from `at` lie in the readable range (always, unchecked).
  bool readable(std::uintptr_t at, std::size_t bytes) const {
    if (!checked()) return true;
    const auto begin = reinterpret_cast<std::uintptr_t>(options_.readable->data());
    const std::uintptr_t end = begin + options_.readable->size();
    return at >= begin && at <= end && bytes <= end - at;
  }

  // Alignments a schema gives that are no power of two are not checked.
  static bool aligned(std::uintptr_t at, std::uint32_t align) {
    const bool power_of_two = align != 0 && (align & (align - 1)) == 0;
    return !power_of_two || at % align == 0;
  }

  const char* root_problem(const void* message, const SchemaType& root) const {
    if (!checked()) return nullptr;
    const auto at = reinterpret_cast<std::uintptr_t>(message);
    if (!readable(at, root.size)) return "message outside the publisher's pool";
    if (!aligned(at, root.align)) return "misaligned message";
    return nullptr;
  }

  // Takes `count` from the budget of values a checked message may show.
  bool spend(std::size_t count) {
    if (!checked()) return true;
    if (count > budget_) return false;
    budget_ -= count;
    return true;
  }

  // The elements of an array or sequence field whose bytes start at `at`.
  // Each pointer is loaded once: a publisher may rewrite it meanwhile.
  Elements elements_of(const SchemaField& field, const std::byte* at) const {
    if (field.shape == FieldShape::Array) return {at, field.array_length};
    const ContainerLayout& layout = schema_.containers;
    const auto begin = load<std::uintptr_t>(at + layout.vector_begin_offset);
    const auto end = load<std::uintptr_t>(at + layout.vector_end_offset);
    const auto* first = reinterpret_cast<const std::byte*>(begin);
    if (!checked()) return {first, (end - begin) / field.element_size};
    if (end < begin) return {.problem = "sequence ends before its begin"};
    const std::size_t bytes = end - begin;
    if (bytes % field.element_size != 0) {
      return {.problem = "sequence length is no whole number of elements"};
    }
    const std::size_t count = bytes / field.element_size;
    if (field.sequence_bound != 0 && count > field.sequence_bound) {
      return {.problem = "sequence longer than its bound"};
    }
    if (count == 0) return {};
    if (!aligned(begin, field.element_align)) return {.problem = "misaligned sequence"};
    if (!readable(begin, bytes)) return {.problem = "sequence outside the publisher's pool"};
    return {first, count};
  }

  // Elements to show: a problem, or the budget exhausted, makes a marker.
  Elements shown_elements(const SchemaField& field, const std::byte* at) {
    Elements elements = elements_of(field, at);
    if (!elements.problem && options_.show_arrays && !spend(elements.count)) {
      elements.problem = "too many values to show";
    }
    return elements;
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

  // `first_prefix` replaces the indentation of the first line (a list item's "- ").
  void text_message(const SchemaType& type, const std::byte* at, std::size_t indent,
                    const std::string& first_prefix) {
    bool first = true;
    for (const SchemaField& field : type.fields) {
      out_ += first && !first_prefix.empty() ? first_prefix : std::string(indent, ' ');
      first = false;
      out_ += field.name;
      out_ += ':';
      const std::byte* value = at + field.offset;
      const bool nested = field.kind == FieldKind::Message;
      if (field.shape == FieldShape::Single) {
        if (nested) {
          out_ += '\n';
          text_message(schema_.types[field.nested], value, indent + 2, "");
        } else {
          out_ += ' ';
          scalar(field, value);
          out_ += '\n';
        }
        continue;
      }
      const Elements elements = shown_elements(field, value);
      if (elements.problem) {
        out_ += ' ';
        marker(elements.problem);
        out_ += '\n';
      } else if (!options_.show_arrays) {
        out_ += " <" + std::to_string(elements.count) + " elements>\n";
      } else if (!nested || elements.count == 0) {
        out_ += " [";
        for (std::size_t i = 0; i < elements.count; ++i) {
          if (i > 0) out_ += ", ";
          scalar(field, elements.first + i * field.element_size);
        }
        out_ += "]\n";
      } else {
        out_ += '\n';
        const std::string item_prefix = std::string(indent + 2, ' ') + "- ";
        for (std::size_t i = 0; i < elements.count; ++i) {
          text_message(schema_.types[field.nested], elements.first + i * field.element_size,
                       indent + 4, item_prefix);
        }
      }
    }
  }

  void json_message(const SchemaType& type, const std::byte* at) {
    out_ += '{';
    bool first = true;
    for (const SchemaField& field : type.fields) {
      if (!first) out_ += ',';
      first = false;
      append_quoted(out_, field.name);
      out_ += ':';
      const std::byte* value = at + field.offset;
      if (field.shape == FieldShape::Single) {
        json_element(field, value);
        continue;
      }
      const Elements elements = shown_elements(field, value);
      if (elements.problem) {
        marker(elements.problem);
        continue;
      }
      if (!options_.show_arrays) {
        out_ += "{\"length\":" + std::to_string(elements.count) + "}";
        continue;
      }
      out_ += '[';
      for (std::size_t i = 0; i < elements.count; ++i) {
        if (i > 0) out_ += ',';
        json_element(field, elements.first + i * field.element_size);
      }
      out_ += ']';
    }
    out_ += '}';
  }

  void json_element(const SchemaField& field, const std::byte* at) {
    if (field.kind == FieldKind::Message) {
      json_message(schema_.types[field.nested], at);
    } else {
      scalar(field, at);
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

  void scalar(const SchemaField& field, const std::byte* at) {
    switch (field.kind) {
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
      case FieldKind::String: {
        const ContainerLayout& layout = schema_.containers;
        const auto data = load<std::uintptr_t>(at + layout.string_data_offset);
        const auto length = load<std::size_t>(at + layout.string_length_offset);
        if (const char* problem = string_problem(field, data, length)) {
          marker(problem);
        } else {
          append_quoted(out_, length == 0
                                  ? ""
                                  : std::string_view(reinterpret_cast<const char*>(data), length));
        }
        break;
      }
      case FieldKind::Opaque:
      case FieldKind::Message:  // a message without its schema: its bytes
        append_bytes(at, field.element_size);
        break;
    }
  }

  const char* string_problem(const SchemaField& field, std::uintptr_t data, std::size_t length) {
    if (!checked() || length == 0) return nullptr;
    if (field.string_bound != 0 && length > field.string_bound) {
      return "string longer than its bound";
    }
    if (!readable(data, length)) return "string outside the publisher's pool";
    if (!spend(length)) return "too many values to show";
    return nullptr;
  }

  const Schema& schema_;
  const RenderOptions& options_;
  std::size_t budget_ = options_.max_values;
  bool json_ = false;
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
