#include "agnocast/schema.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <string_view>

namespace agnocast {
namespace {

constexpr std::size_t type_fixed_bytes = 8 + 4 + 4 + 2 + 1;
constexpr std::size_t field_fixed_bytes = 1 + 1 + 1 + 2 + 7 * 4;

class BlobWriter {
 public:
  void u8(std::uint8_t value) { bytes_.push_back(value); }
  void u16(std::uint16_t value) { little_endian(value, 2); }
  void u32(std::uint32_t value) { little_endian(value, 4); }
  void u64(std::uint64_t value) { little_endian(value, 8); }
  void name(std::string_view text) {
    if (text.empty() || text.size() > 255) {
      throw SchemaError("agnocast: schema names must have 1 to 255 characters: '" +
                        std::string(text) + "'");
    }
    u8(static_cast<std::uint8_t>(text.size()));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
  }
  void text(std::string_view text) {
    u32(static_cast<std::uint32_t>(text.size()));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  void little_endian(std::uint64_t value, int size) {
    for (int i = 0; i < size; ++i) bytes_.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }
  std::vector<std::uint8_t> bytes_;
};

// Every type reachable from `type`, each after all the types it uses (post-order).
void collect_types(const TypeDescriptor& type, std::vector<const TypeDescriptor*>& order) {
  if (std::find(order.begin(), order.end(), &type) != order.end()) return;
  for (const FieldDescriptor& field : type.fields) {
    if (field.nested != nullptr) collect_types(*field.nested, order);
  }
  order.push_back(&type);
}

class BlobReader {
 public:
  explicit BlobReader(std::span<const std::uint8_t> blob) : blob_(blob) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(little_endian(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(little_endian(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(little_endian(4)); }
  std::uint64_t u64() { return little_endian(8); }
  std::string name() {
    const std::size_t length = u8();
    need(length);
    std::string text(reinterpret_cast<const char*>(blob_.data() + position_), length);
    position_ += length;
    if (text.empty() ||
        !std::all_of(text.begin(), text.end(), [](char c) { return c > ' ' && c < 127; })) {
      throw SchemaError("schema: a name is empty or not printable");
    }
    return text;
  }
  // A .msg text: any bytes but NUL (readers hand it on as a C string).
  std::string text() {
    const std::size_t length = u32();
    need(length);
    std::string out(reinterpret_cast<const char*>(blob_.data() + position_), length);
    position_ += length;
    if (out.find('\0') != std::string::npos) throw SchemaError("schema: a definition holds NUL");
    return out;
  }
  bool at_end() const { return position_ == blob_.size(); }

 private:
  void need(std::size_t bytes) const {
    if (bytes > blob_.size() - position_) throw SchemaError("schema: truncated");
  }
  std::uint64_t little_endian(int size) {
    need(static_cast<std::size_t>(size));
    std::uint64_t value = 0;
    for (int i = 0; i < size; ++i) {
      value |= static_cast<std::uint64_t>(blob_[position_ + i]) << (8 * i);
    }
    position_ += static_cast<std::size_t>(size);
    return value;
  }
  std::span<const std::uint8_t> blob_;
  std::size_t position_ = 0;
};

void fail(const SchemaType& type, const SchemaField& field, const char* what) {
  throw SchemaError("schema: " + type.name + "." + field.name + ": " + what);
}

std::uint32_t element_size_of(FieldKind kind, const ContainerLayout& containers) {
  if (kind == FieldKind::String) return containers.string_size;
  return primitive_size(kind);  // 0 for Message and Opaque: checked against their own size
}

void check_field(const Schema& schema, std::size_t type_index, const SchemaField& field) {
  const SchemaType& type = schema.types[type_index];
  const auto kind = static_cast<std::uint8_t>(field.kind);
  if (kind < static_cast<std::uint8_t>(FieldKind::Bool) ||
      kind > static_cast<std::uint8_t>(FieldKind::Opaque)) {
    fail(type, field, "unknown kind");
  }
  if (static_cast<std::uint8_t>(field.shape) > static_cast<std::uint8_t>(FieldShape::Sequence)) {
    fail(type, field, "unknown shape");
  }
  if (field.kind == FieldKind::Message) {
    if (field.nested <= type_index || field.nested >= schema.types.size()) {
      fail(type, field, "nested type index out of order");
    }
    if (schema.types[field.nested].size != field.element_size) {
      fail(type, field, "element size differs from the nested type's size");
    }
  } else if (field.nested != schema_no_type) {
    fail(type, field, "nested type on a field that is not a message");
  }
  if (const std::uint32_t expected = element_size_of(field.kind, schema.containers);
      expected != 0 && expected != field.element_size) {
    fail(type, field, "element size does not match its kind");
  }
  if (field.element_size == 0) fail(type, field, "zero element size");
  if (static_cast<std::uint64_t>(field.offset) + field.size > type.size) {
    fail(type, field, "field beyond the end of its type");
  }
  switch (field.shape) {
    case FieldShape::Single:
      if (field.size != field.element_size) fail(type, field, "size differs from element size");
      break;
    case FieldShape::Array:
      if (static_cast<std::uint64_t>(field.element_size) * field.array_length != field.size) {
        fail(type, field, "array size is not element size times length");
      }
      break;
    case FieldShape::Sequence:
      if (field.size != schema.containers.vector_size) fail(type, field, "not a vector's size");
      break;
  }
}

// A nested type's index is greater than its user's (check_field), so each
// type's depth follows from those after it, last first.
void check_nesting(const Schema& schema) {
  std::vector<std::size_t> depth(schema.types.size(), 1);
  for (std::size_t i = schema.types.size(); i-- > 0;) {
    for (const SchemaField& field : schema.types[i].fields) {
      if (field.kind == FieldKind::Message) depth[i] = std::max(depth[i], depth[field.nested] + 1);
    }
    if (depth[i] > message_max_nesting) {
      throw SchemaError("schema: " + schema.types[i].name + " nests messages " +
                        std::to_string(depth[i]) + " deep, more than the " +
                        std::to_string(message_max_nesting) + " a reader follows");
    }
  }
}

}  // namespace

void require_native_layout(const ContainerLayout& layout, std::string_view type_name,
                           std::string_view purpose) {
  if (layout == native_container_layout()) return;
  throw SchemaError("agnocast: " + std::string(type_name) +
                    " was built with another standard library's container layout than this "
                    "process's, so " +
                    std::string(purpose) +
                    " cannot lay out its vectors and strings; build both with the same compiler "
                    "and standard library");
}

const char* primitive_name(FieldKind kind) {
  switch (kind) {
    case FieldKind::Bool:
      return "bool";
    case FieldKind::Int8:
      return "int8";
    case FieldKind::UInt8:
      return "uint8";
    case FieldKind::Int16:
      return "int16";
    case FieldKind::UInt16:
      return "uint16";
    case FieldKind::Int32:
      return "int32";
    case FieldKind::UInt32:
      return "uint32";
    case FieldKind::Int64:
      return "int64";
    case FieldKind::UInt64:
      return "uint64";
    case FieldKind::Float32:
      return "float32";
    case FieldKind::Float64:
      return "float64";
    case FieldKind::String:
      return "string";
    case FieldKind::Message:
    case FieldKind::Opaque:
      break;
  }
  return nullptr;
}

std::uint32_t primitive_size(FieldKind kind) {
  switch (kind) {
    case FieldKind::Bool:
    case FieldKind::Int8:
    case FieldKind::UInt8:
      return 1;
    case FieldKind::Int16:
    case FieldKind::UInt16:
      return 2;
    case FieldKind::Int32:
    case FieldKind::UInt32:
    case FieldKind::Float32:
      return 4;
    case FieldKind::Int64:
    case FieldKind::UInt64:
    case FieldKind::Float64:
      return 8;
    default:
      return 0;
  }
}

namespace {

std::vector<std::uint8_t> schema_blob(const std::vector<const TypeDescriptor*>& sorted,
                                      bool with_definitions) {
  std::map<const TypeDescriptor*, std::uint16_t> index;
  for (std::size_t i = 0; i < sorted.size(); ++i) index[sorted[i]] = static_cast<std::uint16_t>(i);

  const ContainerLayout& containers = native_container_layout();
  BlobWriter out;
  out.u32(schema_magic);
  out.u16(schema_format_version);
  out.u16(static_cast<std::uint16_t>(sorted.size()));
  out.u32(0);  // total_bytes, filled in below
  for (const std::uint8_t value :
       {containers.pointer_size, containers.vector_size, containers.vector_begin_offset,
        containers.vector_end_offset, containers.string_size, containers.string_data_offset,
        containers.string_length_offset, std::uint8_t{0}}) {
    out.u8(value);
  }
  for (const TypeDescriptor* type : sorted) {
    out.u64(type->hash);
    out.u32(type->size);
    out.u32(type->align);
    out.u16(static_cast<std::uint16_t>(type->fields.size()));
    out.name(type->name);
    for (const FieldDescriptor& field : type->fields) {
      out.name(field.name);
      out.u8(static_cast<std::uint8_t>(field.kind));
      out.u8(static_cast<std::uint8_t>(field.shape));
      out.u16(field.nested != nullptr ? index[field.nested] : schema_no_type);
      for (const std::uint32_t value :
           {field.offset, field.size, field.element_size, field.element_align, field.array_length,
            field.sequence_bound, field.string_bound}) {
        out.u32(value);
      }
    }
  }
  for (const TypeDescriptor* type : sorted) {
    const bool usable = with_definitions && type->definition.size() <= schema_max_bytes &&
                        type->definition.find('\0') == std::string_view::npos;
    out.text(usable ? type->definition : std::string_view{});
  }
  std::vector<std::uint8_t>& blob = out.bytes();
  const auto total = static_cast<std::uint32_t>(blob.size());  // refused when too large
  for (int i = 0; i < 4; ++i) blob[8 + i] = static_cast<std::uint8_t>(total >> (8 * i));
  return std::move(blob);
}

}  // namespace

std::vector<std::uint8_t> build_schema(const TypeDescriptor& root) {
  // Reversed post-order: the message type first, every type before the types it uses.
  std::vector<const TypeDescriptor*> sorted;
  collect_types(root, sorted);
  std::reverse(sorted.begin(), sorted.end());
  std::vector<std::uint8_t> blob = schema_blob(sorted, true);
  // The texts are for people and tools; a type whose texts do not fit still has a schema.
  if (blob.size() > schema_max_bytes) blob = schema_blob(sorted, false);
  if (blob.size() > schema_max_bytes) {
    throw SchemaError("agnocast: the schema of " + std::string(root.name) + " takes " +
                      std::to_string(blob.size()) + " bytes, more than the " +
                      std::to_string(schema_max_bytes) + " a topic can hold");
  }
  // What readers will refuse (nesting too deep) is refused here, at the writer.
  parse_schema(blob);
  return blob;
}

Schema parse_schema(std::span<const std::uint8_t> blob) {
  if (blob.size() > schema_max_bytes) throw SchemaError("schema: larger than schema_max_bytes");
  BlobReader in(blob);
  if (in.u32() != schema_magic) throw SchemaError("schema: bad magic (not an agnocast schema)");
  if (const std::uint16_t version = in.u16(); version != schema_format_version) {
    throw SchemaError("schema: format version " + std::to_string(version) + ", this reader knows " +
                      std::to_string(schema_format_version));
  }
  const std::uint16_t type_count = in.u16();
  if (type_count == 0) throw SchemaError("schema: no type");
  if (in.u32() != blob.size()) throw SchemaError("schema: total_bytes differs from the blob size");
  Schema schema;
  ContainerLayout& containers = schema.containers;
  containers.pointer_size = in.u8();
  containers.vector_size = in.u8();
  containers.vector_begin_offset = in.u8();
  containers.vector_end_offset = in.u8();
  containers.string_size = in.u8();
  containers.string_data_offset = in.u8();
  containers.string_length_offset = in.u8();
  in.u8();
  if (containers.pointer_size != sizeof(void*) ||
      containers.vector_begin_offset + sizeof(void*) > containers.vector_size ||
      containers.vector_end_offset + sizeof(void*) > containers.vector_size ||
      containers.string_data_offset + sizeof(void*) > containers.string_size ||
      containers.string_length_offset + sizeof(std::size_t) > containers.string_size) {
    throw SchemaError("schema: container layout unusable on this machine");
  }
  // Each type and field takes at least its fixed bytes: counts beyond that are lies.
  if (static_cast<std::size_t>(type_count) * type_fixed_bytes > blob.size()) {
    throw SchemaError("schema: truncated");
  }
  schema.types.resize(type_count);
  for (SchemaType& type : schema.types) {
    type.hash = in.u64();
    type.size = in.u32();
    type.align = in.u32();
    const std::uint16_t field_count = in.u16();
    if (static_cast<std::size_t>(field_count) * field_fixed_bytes > blob.size()) {
      throw SchemaError("schema: truncated");
    }
    type.name = in.name();
    type.fields.resize(field_count);
    for (SchemaField& field : type.fields) {
      field.name = in.name();
      field.kind = static_cast<FieldKind>(in.u8());
      field.shape = static_cast<FieldShape>(in.u8());
      field.nested = in.u16();
      field.offset = in.u32();
      field.size = in.u32();
      field.element_size = in.u32();
      field.element_align = in.u32();
      field.array_length = in.u32();
      field.sequence_bound = in.u32();
      field.string_bound = in.u32();
    }
  }
  for (SchemaType& type : schema.types) type.definition = in.text();
  if (!in.at_end()) throw SchemaError("schema: bytes after the last definition");
  for (std::size_t i = 0; i < schema.types.size(); ++i) {
    for (const SchemaField& field : schema.types[i].fields) check_field(schema, i, field);
  }
  check_nesting(schema);
  return schema;
}

}  // namespace agnocast
