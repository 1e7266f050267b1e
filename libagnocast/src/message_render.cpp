#include "agnocast/message_render.hpp"

#include <charconv>
#include <cmath>
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
    if (root.fields.empty()) {
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
    if (root.fields.empty()) {
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
    const std::byte* first;
    std::size_t count;
    bool readable;
  };

  bool readable(const void* address, std::size_t bytes) const {
    return !options_.readable || options_.readable(address, bytes);
  }

  // The elements of an array or sequence field whose bytes start at `at`.
  Elements elements_of(const SchemaField& field, const std::byte* at) const {
    if (field.shape == FieldShape::Array) return {at, field.array_length, true};
    const ContainerLayout& layout = schema_.containers;
    const auto begin = load<std::uintptr_t>(at + layout.vector_begin_offset);
    const auto end = load<std::uintptr_t>(at + layout.vector_end_offset);
    const std::uintptr_t bytes = end - begin;
    const auto* first = reinterpret_cast<const std::byte*>(begin);
    if (end < begin || bytes % field.element_size != 0 || !readable(first, bytes)) {
      return {nullptr, 0, false};
    }
    return {first, bytes / field.element_size, true};
  }

  void unreadable() { out_ += json_ ? "null" : "<unreadable>"; }

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
      const Elements elements = elements_of(field, value);
      if (!elements.readable) {
        out_ += ' ';
        unreadable();
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
      const Elements elements = elements_of(field, value);
      if (!elements.readable) {
        unreadable();
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
        const auto* data = load<const char*>(at + layout.string_data_offset);
        const auto length = load<std::size_t>(at + layout.string_length_offset);
        if (readable(data, length)) {
          append_quoted(out_, std::string_view(data, length));
        } else {
          unreadable();
        }
        break;
      }
      case FieldKind::Opaque:
      case FieldKind::Message:  // a message without its schema: its bytes
        append_bytes(at, field.element_size);
        break;
    }
  }

  const Schema& schema_;
  const RenderOptions& options_;
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
