// agnocast._core: the Python binding. One generic message accessor serves
// every message type: a type is its schema blob (agnocast::build_schema of the
// generated C++ type, emitted beside the Python message modules), and fields
// are read and written in place in the pool at the offsets it gives. Arrays of
// numbers are numpy arrays over the pool memory, never copies.
//
// The GIL is released while the library waits or calls the kernel; callbacks
// take it back to run Python.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "agnocast/agnocast.hpp"
#include "agnocast/detail/endpoints.hpp"
#include "agnocast/detail/message.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/log.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_client.hpp"
#include "agnocast/schema_definition.hpp"
#include "agnocast/schema_service.hpp"
#include "agnocast/schema_subscriber.hpp"
#include "erased_message.hpp"
#include "log_forwarder.hpp"

namespace py = pybind11;

namespace agnocast::python {
namespace {

// Using a message after publish() handed it over.
class MessagePublished : public Error {
 public:
  using Error::Error;
};
// Writing to a received message, which lives read-only in the publisher's pool.
class ReadOnlyMessage : public Error {
 public:
  using Error::Error;
};

// A message type, alive for the whole process: a published message may be
// destroyed (when the kernel reports it reclaimable) long after the Python
// objects that made it are gone.
struct MessageClass {
  MessageClass(std::vector<std::uint8_t> blob, std::string default_image)
      : schema(std::move(blob)), ops(schema), defaults(std::move(default_image)) {
    if (!defaults.empty() && defaults.size() != type().size) {
      throw SchemaError("agnocast: the default values of " + type().name + " have the wrong size");
    }
  }
  ErasedSchema schema;
  ErasedOps ops;
  // A default-constructed message's bytes (empty: all zero); only its
  // number fields are used, those of nested messages included.
  std::string defaults;
  const SchemaType& type() const { return schema.type(0); }

  // Gives a new message the .msg file's default values, as C++ construction does.
  void apply_defaults(std::byte* message, const std::byte* image, std::uint16_t index) const {
    for (const SchemaField& field : schema.type(index).fields) {
      if (field.shape == FieldShape::Sequence || field.kind == FieldKind::String) continue;
      if (field.kind != FieldKind::Message) {
        std::memcpy(message + field.offset, image + field.offset, field.size);
        continue;
      }
      const std::size_t count = field.shape == FieldShape::Array ? field.array_length : 1;
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t at = field.offset + i * field.element_size;
        apply_defaults(message + at, image + at, field.nested);
      }
    }
  }
};

std::mutex& class_mutex() {
  static auto* mutex = new std::mutex;
  return *mutex;
}
// Every message class made, never freed (see MessageClass).
std::unordered_map<std::string, MessageClass*>& classes() {
  static auto* map = new std::unordered_map<std::string, MessageClass*>;
  return *map;
}
// The class of every loaned message, for its destroy function.
std::unordered_map<void*, const MessageClass*>& loans() {
  static auto* map = new std::unordered_map<void*, const MessageClass*>;
  return *map;
}

void destroy_erased(void* message) {
  const MessageClass* cls = nullptr;
  {
    std::lock_guard lock(class_mutex());
    const auto found = loans().find(message);
    if (found == loans().end()) return;
    cls = found->second;
    loans().erase(found);
  }
  cls->ops.destroy(message, 0);
}

const MessageClass* message_class(py::bytes blob_bytes, py::bytes default_image) {
  const std::string text = blob_bytes;
  std::lock_guard lock(class_mutex());
  auto& map = classes();
  if (const auto found = map.find(text); found != map.end()) return found->second;
  auto* cls = new MessageClass(std::vector<std::uint8_t>(text.begin(), text.end()),
                               std::string(default_image));
  map.emplace(text, cls);
  return cls;
}

// A Python callable whose last reference may be dropped by an executor
// thread that does not hold the GIL.
class Callback {
 public:
  explicit Callback(py::object function)
      : function_(new py::object(std::move(function)), [](py::object* object) {
          if (!Py_IsInitialized()) return;  // the interpreter is gone: leak it
          py::gil_scoped_acquire gil;
          delete object;
        }) {}
  const py::object& operator*() const { return *function_; }

 private:
  std::shared_ptr<py::object> function_;
};

// A message's memory: a loan until published, or a received entry held.
struct Storage {
  const MessageClass* cls = nullptr;
  void* message = nullptr;
  bool loan = false;
  bool published = false;
  detail::EntryReference* reference = nullptr;
  // A service's request or response, held instead of a reference.
  std::optional<SchemaMessage> held;
  // What a read may touch: everything for a loan, the publisher's pool for a
  // received message, whose every pointer is the publisher's to write.
  ForeignMemory memory;
  const char* problem = nullptr;  // a received message that is not where it must be

  ~Storage() {
    if (reference) {
      detail::release(reference);
    } else if (loan && !published && message) {
      detail::discard_message(message);
    }
  }
  void check() const {
    if (published) {
      throw MessagePublished(
          "agnocast: this message was published; borrow a new one with "
          "borrow_loaned_message()");
    }
    if (problem) {
      throw InvalidMessage("agnocast: a received " + cls->schema.type(0).name + ": " + problem);
    }
  }
};

struct Message;
py::object field_value(const std::shared_ptr<Storage>& storage, std::byte* base,
                       const SchemaField& field);
void set_field(const std::shared_ptr<Storage>& storage, std::byte* base, const SchemaField& field,
               py::handle value);

// A message or a nested message of one, sharing the storage.
struct Message {
  std::shared_ptr<Storage> storage;
  std::byte* base = nullptr;
  std::uint16_t index = 0;

  const SchemaType& type() const { return storage->cls->schema.type(index); }
  bool writable() const { return storage->loan; }

  const SchemaField& field(const std::string& name) const {
    const SchemaField* found = storage->cls->schema.field(index, name);
    if (!found) throw py::attribute_error(type().name + " has no field '" + name + "'");
    return *found;
  }
  py::object get(const std::string& name) const {
    const SchemaField& target = field(name);  // AttributeError first, for hasattr()
    storage->check();
    return field_value(storage, base, target);
  }
  void set(const std::string& name, py::handle value) const {
    const SchemaField& target = field(name);
    storage->check();
    if (!writable()) {
      throw ReadOnlyMessage("agnocast: a received message is read-only (field '" + name + "' of " +
                            type().name + ")");
    }
    set_field(storage, base, target, value);
  }
};

// The Python classes of the message types, by layout hash (agnocast._message
// registers each class it makes). Touched only with the GIL held.
std::unordered_map<std::uint64_t, py::object>& python_classes() {
  static auto* map = new std::unordered_map<std::uint64_t, py::object>;
  return *map;
}

// agnocast._core.Message.__init__, which makes an instance of a message class
// share a core message's memory (set when the module loads).
py::object& core_message_init() {
  static auto* init = new py::object;
  return *init;
}

// The message as an instance of its type's class (PointCloud2, Header, ...).
py::object to_python(Message message) {
  const SchemaType& type = message.type();
  auto& known = python_classes();
  auto found = known.find(type.hash);
  if (found == known.end()) {
    // A nested type whose module was not imported: _message makes its class.
    py::module_::import("agnocast._message").attr("class_for")(type.name, type.hash);
    found = known.find(type.hash);
    if (found == known.end()) return py::cast(std::move(message));
  }
  // Made as Python makes an instance, but without the class's own __init__,
  // which would borrow a new message.
  const py::object& cls = found->second;
  py::object object = cls.attr("__new__")(cls);
  core_message_init()(object, py::cast(std::move(message)));
  return object;
}

// A sequence or fixed array field: numbers (buffer protocol, numpy views),
// strings or messages.
struct Sequence {
  std::shared_ptr<Storage> storage;
  std::byte* address = nullptr;  // the field
  const SchemaField* field = nullptr;

  bool writable() const { return storage->loan; }
  const ErasedOps& ops() const { return storage->cls->ops; }
  VectorSpan elements() const {
    storage->check();
    if (field->shape == FieldShape::Sequence)
      return ops().sequence(address, *field, storage->memory);
    return {address, field->array_length};
  }
  std::size_t length() const { return elements().count; }
  void resize(std::size_t count) const {
    storage->check();
    if (!writable()) throw ReadOnlyMessage("agnocast: a received message is read-only");
    if (field->shape != FieldShape::Sequence) {
      throw py::type_error("agnocast: '" + field->name + "' is a fixed-size array");
    }
    if (field->sequence_bound && count > field->sequence_bound) {
      throw py::value_error("agnocast: '" + field->name + "' holds at most " +
                            std::to_string(field->sequence_bound) + " elements");
    }
    ops().resize_sequence(address, *field, count);
  }
  std::byte* element(std::ptrdiff_t i) const {
    const VectorSpan span = elements();
    const auto count = static_cast<std::ptrdiff_t>(span.count);
    if (i < 0) i += count;
    if (i < 0 || i >= count) throw py::index_error("agnocast: index out of range");
    return span.data + i * field->element_size;
  }
};

py::dtype dtype_of(FieldKind kind) {
  switch (kind) {
    case FieldKind::Bool:
      return py::dtype::of<bool>();
    case FieldKind::Int8:
      return py::dtype::of<std::int8_t>();
    case FieldKind::UInt8:
      return py::dtype::of<std::uint8_t>();
    case FieldKind::Int16:
      return py::dtype::of<std::int16_t>();
    case FieldKind::UInt16:
      return py::dtype::of<std::uint16_t>();
    case FieldKind::Int32:
      return py::dtype::of<std::int32_t>();
    case FieldKind::UInt32:
      return py::dtype::of<std::uint32_t>();
    case FieldKind::Int64:
      return py::dtype::of<std::int64_t>();
    case FieldKind::UInt64:
      return py::dtype::of<std::uint64_t>();
    case FieldKind::Float32:
      return py::dtype::of<float>();
    case FieldKind::Float64:
      return py::dtype::of<double>();
    default:
      throw py::type_error("agnocast: not a number field");
  }
}

// What the array's base holds: the message stays alive while any view does.
struct Keeper {
  std::shared_ptr<Storage> storage;
};

// A numpy array over count numbers at data; read-only unless the message is a loan.
py::array number_view(const std::shared_ptr<Storage>& storage, std::byte* data, FieldKind kind,
                      std::size_t count) {
  static std::uint64_t empty = 0;  // numpy wants an address even for no elements
  py::object base = py::cast(Keeper{storage});
  py::array array(dtype_of(kind), {static_cast<py::ssize_t>(count)}, {},
                  data ? static_cast<void*>(data) : static_cast<void*>(&empty), base);
  if (!storage->loan || !data) array.attr("setflags")(py::arg("write") = false);
  return array;
}

py::object read_number(const std::byte* at, FieldKind kind) {
  auto load = [at]<class T>(T) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
  };
  switch (kind) {
    case FieldKind::Bool:
      return py::bool_(*reinterpret_cast<const std::uint8_t*>(at) != 0);
    case FieldKind::Int8:
      return py::int_(load(std::int8_t{}));
    case FieldKind::UInt8:
      return py::int_(load(std::uint8_t{}));
    case FieldKind::Int16:
      return py::int_(load(std::int16_t{}));
    case FieldKind::UInt16:
      return py::int_(load(std::uint16_t{}));
    case FieldKind::Int32:
      return py::int_(load(std::int32_t{}));
    case FieldKind::UInt32:
      return py::int_(load(std::uint32_t{}));
    case FieldKind::Int64:
      return py::int_(load(std::int64_t{}));
    case FieldKind::UInt64:
      return py::int_(load(std::uint64_t{}));
    case FieldKind::Float32:
      return py::float_(load(float{}));
    case FieldKind::Float64:
      return py::float_(load(double{}));
    default:
      throw py::type_error("agnocast: not a number field");
  }
}

template <class T>
void store_integer(std::byte* at, py::handle value, const std::string& name) {
  if (!py::isinstance<py::int_>(value) && !py::hasattr(value, "__index__")) {
    throw py::type_error("agnocast: field '" + name + "' takes an int");
  }
  const auto wide = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!wide) throw py::error_already_set();
  long long big = 0;
  unsigned long long ubig = 0;
  bool in_range;
  if constexpr (std::is_signed_v<T>) {
    big = PyLong_AsLongLong(wide.ptr());
    in_range = !PyErr_Occurred() && big >= std::numeric_limits<T>::min() &&
               big <= std::numeric_limits<T>::max();
  } else {
    ubig = PyLong_AsUnsignedLongLong(wide.ptr());
    in_range = !PyErr_Occurred() && ubig <= std::numeric_limits<T>::max();
  }
  if (!in_range) {
    PyErr_Clear();
    throw py::value_error("agnocast: " + py::repr(value).cast<std::string>() +
                          " does not fit field '" + name + "'");
  }
  const T stored = std::is_signed_v<T> ? static_cast<T>(big) : static_cast<T>(ubig);
  std::memcpy(at, &stored, sizeof(T));
}

void write_number(std::byte* at, FieldKind kind, py::handle value, const std::string& name) {
  switch (kind) {
    case FieldKind::Bool: {
      const std::uint8_t flag = py::cast<bool>(value) ? 1 : 0;
      std::memcpy(at, &flag, 1);
      return;
    }
    case FieldKind::Int8:
      return store_integer<std::int8_t>(at, value, name);
    case FieldKind::UInt8:
      return store_integer<std::uint8_t>(at, value, name);
    case FieldKind::Int16:
      return store_integer<std::int16_t>(at, value, name);
    case FieldKind::UInt16:
      return store_integer<std::uint16_t>(at, value, name);
    case FieldKind::Int32:
      return store_integer<std::int32_t>(at, value, name);
    case FieldKind::UInt32:
      return store_integer<std::uint32_t>(at, value, name);
    case FieldKind::Int64:
      return store_integer<std::int64_t>(at, value, name);
    case FieldKind::UInt64:
      return store_integer<std::uint64_t>(at, value, name);
    case FieldKind::Float32: {
      const auto number = static_cast<float>(py::cast<double>(value));
      std::memcpy(at, &number, sizeof(number));
      return;
    }
    case FieldKind::Float64: {
      const auto number = py::cast<double>(value);
      std::memcpy(at, &number, sizeof(number));
      return;
    }
    default:
      throw py::type_error("agnocast: not a number field");
  }
}

py::str decode(std::string_view text) {
  PyObject* object =
      PyUnicode_DecodeUTF8(text.data(), static_cast<py::ssize_t>(text.size()), "surrogateescape");
  if (!object) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(object);
}

void write_string(const ErasedOps& ops, std::byte* at, py::handle value, const SchemaField& field) {
  std::string text;
  if (py::isinstance<py::bytes>(value)) {
    text = py::cast<std::string>(value);
  } else if (py::isinstance<py::str>(value)) {
    const auto encoded = py::reinterpret_steal<py::object>(
        PyUnicode_AsEncodedString(value.ptr(), "utf-8", "surrogateescape"));
    if (!encoded) throw py::error_already_set();
    text = py::cast<std::string>(encoded);
  } else {
    throw py::type_error("agnocast: field '" + field.name + "' takes a str");
  }
  if (field.string_bound && text.size() > field.string_bound) {
    throw py::value_error("agnocast: field '" + field.name + "' holds at most " +
                          std::to_string(field.string_bound) + " bytes");
  }
  ops.assign_string(at, text);
}

py::object field_value(const std::shared_ptr<Storage>& storage, std::byte* base,
                       const SchemaField& field) {
  std::byte* at = base + field.offset;
  const ErasedOps& ops = storage->cls->ops;
  if (field.shape == FieldShape::Single) {
    if (field.kind == FieldKind::String) return decode(ops.string_at(at, field, storage->memory));
    if (field.kind == FieldKind::Message) return to_python(Message{storage, at, field.nested});
    return read_number(at, field.kind);
  }
  if (field.shape == FieldShape::Array && is_primitive(field.kind)) {
    return number_view(storage, at, field.kind, field.array_length);
  }
  return py::cast(Sequence{storage, at, &field});
}

void assign_numbers(const Sequence& sequence, py::handle value) {
  const SchemaField& field = *sequence.field;
  if (py::isinstance<Sequence>(value)) {
    // Another message's numbers, read through its checks (numpy would hide
    // their error behind its own).
    const auto& from = py::cast<const Sequence&>(value);
    if (from.field->kind == field.kind) {
      const VectorSpan source = from.elements();
      if (field.shape == FieldShape::Sequence) {
        sequence.resize(source.count);
      } else if (source.count != field.array_length) {
        throw py::value_error("agnocast: field '" + field.name + "' holds exactly " +
                              std::to_string(field.array_length) + " elements");
      }
      const VectorSpan target = sequence.elements();
      if (source.count) std::memmove(target.data, source.data, source.count * field.element_size);
      return;
    }
  }
  py::array source = py::array::ensure(value);
  if (!source) throw py::type_error("agnocast: field '" + field.name + "' takes numbers");
  source = py::array(py::module_::import("numpy").attr("ascontiguousarray")(source.attr("ravel")(),
                                                                            dtype_of(field.kind)));
  const auto count = static_cast<std::size_t>(source.size());
  if (field.shape == FieldShape::Sequence) {
    sequence.resize(count);
  } else if (count != field.array_length) {
    throw py::value_error("agnocast: field '" + field.name + "' holds exactly " +
                          std::to_string(field.array_length) + " elements");
  }
  const VectorSpan target = sequence.elements();
  if (count) std::memcpy(target.data, source.data(), count * field.element_size);
}

void set_field(const std::shared_ptr<Storage>& storage, std::byte* base, const SchemaField& field,
               py::handle value) {
  std::byte* at = base + field.offset;
  const ErasedOps& ops = storage->cls->ops;
  if (field.shape == FieldShape::Single) {
    if (field.kind == FieldKind::String) return write_string(ops, at, value, field);
    if (field.kind == FieldKind::Message) {
      const auto& source = py::cast<const Message&>(value);
      source.storage->check();
      const SchemaType& want = storage->cls->schema.type(field.nested);
      if (source.type().hash != want.hash) {
        throw py::type_error("agnocast: field '" + field.name + "' takes a " + want.name +
                             ", not a " + source.type().name);
      }
      // Same layout (the hash says so), possibly described by another schema object.
      source.storage->cls->ops.copy(at, source.base, source.index, source.storage->memory);
      return;
    }
    return write_number(at, field.kind, value, field.name);
  }
  const Sequence sequence{storage, at, &field};
  if (is_primitive(field.kind)) return assign_numbers(sequence, value);
  const py::list items = py::list(py::iter(value));
  const auto count = static_cast<std::size_t>(items.size());
  if (field.shape == FieldShape::Sequence) {
    sequence.resize(count);
  } else if (count != field.array_length) {
    throw py::value_error("agnocast: field '" + field.name + "' holds exactly " +
                          std::to_string(field.array_length) + " elements");
  }
  for (std::size_t i = 0; i < count; ++i) {
    std::byte* element = sequence.element(static_cast<std::ptrdiff_t>(i));
    if (field.kind == FieldKind::String) {
      write_string(ops, element, items[i], field);
    } else {
      const auto& source = py::cast<const Message&>(items[i]);
      source.storage->check();
      if (source.type().hash != storage->cls->schema.type(field.nested).hash) {
        throw py::type_error("agnocast: elements of '" + field.name + "' have another type");
      }
      source.storage->cls->ops.copy(element, source.base, source.index, source.storage->memory);
    }
  }
}

// Sets the Python error for the exception being handled, through the same
// translators every bound function's errors go through (ours first).
void raise_current_exception() {
  if (py::detail::apply_exception_translators(
          py::detail::get_local_internals().registered_exception_translators) ||
      py::detail::apply_exception_translators(
          py::detail::get_internals().registered_exception_translators)) {
    return;
  }
  PyErr_SetString(PyExc_SystemError, "agnocast: an error no translator knows");
}

// What a Sequence's buffer view points its format, shape and strides at.
struct SequenceBuffer {
  std::string format;
  py::ssize_t shape;
  py::ssize_t stride;
};

// The buffer protocol of a Sequence of numbers (numpy views, memoryview),
// written out rather than by pybind11's def_buffer, whose getter must not
// throw: a received sequence pointing outside the publisher's pool raises
// InvalidMessage here, and the view is made from the words read and checked once.
extern "C" int sequence_getbuffer(PyObject* object, Py_buffer* view, int flags) {
  view->obj = nullptr;
  try {
    const auto& sequence = py::cast<const Sequence&>(py::handle(object));
    const SchemaField& field = *sequence.field;
    if (!is_primitive(field.kind)) {
      throw py::type_error("agnocast: only fields of numbers are buffers");
    }
    if ((flags & PyBUF_WRITABLE) == PyBUF_WRITABLE && !sequence.writable()) {
      throw py::buffer_error("agnocast: a received message is read-only");
    }
    static std::uint64_t empty = 0;
    const VectorSpan span = sequence.elements();
    const auto size = static_cast<py::ssize_t>(field.element_size);
    auto* buffer =
        new SequenceBuffer{py::str(dtype_of(field.kind).attr("char")).cast<std::string>(),
                           static_cast<py::ssize_t>(span.count), size};
    view->buf = span.data ? static_cast<void*>(span.data) : &empty;
    view->len = buffer->shape * size;
    view->itemsize = size;
    view->readonly = sequence.writable() ? 0 : 1;
    view->ndim = 1;
    view->format = (flags & PyBUF_FORMAT) == PyBUF_FORMAT ? buffer->format.data() : nullptr;
    view->shape = (flags & PyBUF_ND) == PyBUF_ND ? &buffer->shape : nullptr;
    view->strides = (flags & PyBUF_STRIDES) == PyBUF_STRIDES ? &buffer->stride : nullptr;
    view->suboffsets = nullptr;
    view->internal = buffer;
    view->obj = object;
    Py_INCREF(object);
    return 0;
  } catch (...) {
    raise_current_exception();
    return -1;
  }
}

extern "C" void sequence_releasebuffer(PyObject*, Py_buffer* view) {
  delete static_cast<SequenceBuffer*>(view->internal);
}

py::dict info_dict(const MessageInfo& info) {
  py::dict out;
  out["publisher_id"] = info.publisher_id;
  out["entry_id"] = info.entry_id;
  out["publish_time"] = info.publish_time;
  out["bytes"] = info.bytes;
  return out;
}

Message received(const MessageClass* cls, const void* message, detail::EntryReference* reference) {
  auto storage = std::make_shared<Storage>();
  storage->cls = cls;
  storage->message = const_cast<void*>(message);
  storage->reference = reference;
  storage->memory = ForeignMemory(detail::pool_holding(message));
  storage->problem = message_problem(cls->type(), message, storage->memory);
  return Message{storage, static_cast<std::byte*>(storage->message), 0};
}

// A service's request or response, read in place where its sender wrote it.
Message received(const MessageClass* cls, SchemaMessage&& message) {
  auto storage = std::make_shared<Storage>();
  storage->cls = cls;
  storage->message = const_cast<void*>(message.data());
  storage->memory = ForeignMemory(message.readable());
  storage->problem = message_problem(cls->type(), message.data(), storage->memory);
  storage->held.emplace(std::move(message));
  return Message{storage, static_cast<std::byte*>(storage->message), 0};
}

detail::MessageType type_of(const MessageClass* cls) {
  return detail::MessageType{cls->type().name, cls->type().hash, cls->schema.blob()};
}

// A new message in this process's pool with the .msg file's default values:
// a loan any publisher of its type may publish.
Message new_loan(const MessageClass* cls) {
  const SchemaType& type = cls->type();
  void* memory = detail::allocate_message(type.size, type.align, &destroy_erased);
  try {
    cls->ops.construct(memory, 0);
    if (!cls->defaults.empty()) {
      cls->apply_defaults(static_cast<std::byte*>(memory),
                          reinterpret_cast<const std::byte*>(cls->defaults.data()), 0);
    }
  } catch (...) {
    detail::free_message_memory(memory);
    throw;
  }
  {
    std::lock_guard lock(class_mutex());
    loans().emplace(memory, cls);
  }
  auto storage = std::make_shared<Storage>();
  storage->cls = cls;
  storage->message = memory;
  storage->loan = true;
  return Message{storage, static_cast<std::byte*>(memory), 0};
}

// The loan of a message of its own (borrowed, or made by calling its class),
// handed over to be sent: the message object is spent from here on.
void* hand_over(const Message& message, const MessageClass* cls, const char* what) {
  Storage& storage = *message.storage;
  if (!storage.loan || message.base != storage.message) {
    throw py::value_error(std::string("agnocast: ") + what +
                          " needs a message from borrow_loaned_message(), not a received or "
                          "nested one");
  }
  storage.check();
  if (storage.cls->type().hash != cls->type().hash) {
    throw py::type_error(std::string("agnocast: ") + what + " takes a " + cls->type().name +
                         ", not a " + storage.cls->type().name);
  }
  storage.published = true;
  return storage.message;
}

class PyPublisher {
 public:
  PyPublisher(const Node& node, const MessageClass* cls, const std::string& topic, const QoS& qos)
      : cls_(cls), core_(node.state(), topic, qos, type_of(cls)) {}

  py::object borrow() { return to_python(new_loan(cls_)); }

  void publish(const Message& message) {
    void* memory = hand_over(message, cls_, "publish");
    const std::uint64_t bytes = detail::published_bytes(memory, cls_->type().size);
    py::gil_scoped_release release;
    core_.publish(memory, bytes);
  }

  std::size_t subscription_count() const {
    py::gil_scoped_release release;
    return core_.subscription_count();
  }
  bool wait_for_subscribers(std::size_t count, double timeout) const {
    py::gil_scoped_release release;
    return core_.wait_for_subscribers(
        count, std::chrono::nanoseconds(static_cast<std::int64_t>(timeout * 1e9)));
  }
  const std::string& topic() const { return core_.topic(); }

 private:
  const MessageClass* cls_;
  detail::PublisherCore core_;
};

class PySubscription : public detail::SubscriptionBase {
 public:
  PySubscription(const Node& node, const MessageClass* cls, const std::string& topic,
                 const QoS& qos, Callback callback, const SubscriptionOptions& options)
      : SubscriptionBase(node.state(), topic, qos, type_of(cls), options),
        cls_(cls),
        callback_(std::move(callback)) {}

  std::size_t publisher_count() const {
    py::gil_scoped_release release;
    return detail::publisher_count(topic());
  }

 private:
  void deliver(const void* message, detail::EntryReference* reference,
               const MessageInfo& info) override {
    py::gil_scoped_acquire gil;
    Message view = received(cls_, message, reference);  // owns the reference from here
    (*callback_)(to_python(std::move(view)), info_dict(info));
  }

  const MessageClass* cls_;
  Callback callback_;
};

class PyPolling {
 public:
  PyPolling(const Node& node, const MessageClass* cls, const std::string& topic, const QoS& qos,
            const SubscriptionOptions& options)
      : cls_(cls), core_(node.state(), topic, qos, type_of(cls), options) {}

  py::object take(bool only_new) {
    detail::TakenEntry taken;
    {
      py::gil_scoped_release release;
      taken = only_new ? core_.take_new() : core_.take_latest();
    }
    if (!taken.message) return py::none();
    return to_python(received(cls_, taken.message, taken.reference));
  }
  std::size_t publisher_count() const {
    py::gil_scoped_release release;
    return detail::publisher_count(core_.topic());
  }
  const std::string& topic() const { return core_.topic(); }

 private:
  const MessageClass* cls_;
  detail::PollingCore core_;
};

// What a topic carrying the class's messages registers.
SchemaTopic schema_topic(std::string topic, const MessageClass* cls) {
  SchemaTopic part;
  part.topic = std::move(topic);
  part.type_name = cls->type().name;
  part.type_hash = cls->type().hash;
  const auto blob = cls->schema.blob();
  part.blob.assign(blob.begin(), blob.end());
  part.schema = cls->schema.schema();
  return part;
}

ServiceTypes service_types(const std::string& service, const MessageClass* request,
                           const MessageClass* response) {
  validate_service_name(service);
  return {schema_topic(service_request_topic(service), request),
          schema_topic(service_reply_topic(service), response)};
}

// The Python exception a failed call's exception is (ServiceUnavailable, ...).
py::object exception_object(std::exception_ptr error) {
  try {
    std::rethrow_exception(error);
  } catch (...) {
    raise_current_exception();
  }
  PyObject* type = nullptr;
  PyObject* value = nullptr;
  PyObject* trace = nullptr;
  PyErr_Fetch(&type, &value, &trace);
  PyErr_NormalizeException(&type, &value, &trace);
  if (trace) PyException_SetTraceback(value, trace);
  Py_XDECREF(type);
  Py_XDECREF(trace);
  return py::reinterpret_steal<py::object>(value);
}

// agnocast.InvalidMessage (set when the module loads).
py::object& invalid_message_type() {
  static auto* type = new py::object;
  return *type;
}

std::chrono::nanoseconds timeout_of(const py::object& seconds) {
  // None waits as good as forever: a century.
  if (seconds.is_none()) return std::chrono::hours(24 * 365 * 100);
  const double value = py::cast<double>(seconds);
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::max(value, 0.0) * 1e9));
}

// A server: each request, read in place in the client's pool, and a new
// response from this process's pool go to the Python callback, which fills
// the response; it is sent when the callback returns.
class PyService {
 public:
  PyService(Node& node, const MessageClass* request, const MessageClass* response,
            const std::string& service, const QoS& qos, Callback callback,
            std::shared_ptr<CallbackGroup> group)
      : service_(node, service, service_types(service, request, response),
                 [service, request, response, callback = std::move(callback)](
                     SchemaMessage message, SchemaService::Responder responder) {
                   answer(service, request, response, callback, std::move(message), responder);
                 },
                 qos, std::move(group)) {}

  const std::string& name() const { return service_.service_name(); }

 private:
  // Runs on the executor's thread; captures nothing of the PyService, which
  // Python may destroy while a request waits for the GIL.
  static void answer(const std::string& service, const MessageClass* request_class,
                     const MessageClass* response_class, const Callback& callback,
                     SchemaMessage request, const SchemaService::Responder& responder) {
    py::gil_scoped_acquire gil;
    const py::object request_object = to_python(received(request_class, std::move(request)));
    const Message response = new_loan(response_class);
    const py::object response_object = to_python(response);
    py::object returned;
    try {
      returned = (*callback)(request_object, response_object);
    } catch (py::error_already_set& error) {
      // A request whose containers lie is the client's fault: refused, and
      // the server carries on. Any other exception stops spin(), as a
      // subscription's does.
      if (!error.matches(invalid_message_type())) throw;
      py::module_::import("logging")
          .attr("getLogger")("agnocast")
          .attr("warning")("agnocast: service " + service +
                           ": a request of client " + std::to_string(responder.id().client) +
                           " was refused unanswered: " + py::str(error.value()).cast<std::string>());
      return;
    }
    // The callback may also return the response, as rclpy's do.
    Message sent = response;
    if (!returned.is_none() && !returned.is(response_object)) sent = py::cast<Message>(returned);
    void* memory = hand_over(sent, response_class, "a service's response");
    const std::uint64_t bytes = detail::published_bytes(memory, response_class->type().size);
    py::gil_scoped_release release;
    responder.send(memory, bytes);
  }

  SchemaService service_;
};

// A client: requests are messages of their own in this process's pool, each
// response is read in place in the server's pool.
class PyClient {
 public:
  PyClient(Node& node, const MessageClass* request, const MessageClass* response,
           const std::string& service, const QoS& qos, std::shared_ptr<CallbackGroup> group)
      : request_(request),
        response_(response),
        client_(node, service, service_types(service, request, response), qos, std::move(group)) {}

  py::object borrow() { return to_python(new_loan(request_)); }

  // Waits for the answer without the GIL; TimeoutError when none came.
  py::object call(const Message& request, const py::object& timeout_sec) {
    const std::chrono::nanoseconds timeout = timeout_of(timeout_sec);
    void* memory = hand_over(request, request_, "call");
    const std::uint64_t bytes = detail::published_bytes(memory, request_->type().size);
    std::optional<SchemaMessage> response = [&] {
      py::gil_scoped_release release;
      return client_.call(memory, bytes, timeout);
    }();
    if (!response) {
      PyErr_SetString(PyExc_TimeoutError,
                      ("agnocast: service " + client_.service_name() + " did not answer within " +
                       py::str(timeout_sec).cast<std::string>() + " s")
                          .c_str());
      throw py::error_already_set();
    }
    return to_python(received(response_, std::move(*response)));
  }

  // done(response, None) or done(None, exception), once, from the executor
  // spinning the node (or at once, when the request failed at the start).
  py::tuple send(const Message& request, py::object done) {
    void* memory = hand_over(request, request_, "call_async");
    const std::uint64_t bytes = detail::published_bytes(memory, request_->type().size);
    Callback held(std::move(done));
    const MessageClass* response_class = response_;
    RequestId id;
    {
      py::gil_scoped_release release;
      id = client_.send(memory, bytes,
                        [held, response_class](std::optional<SchemaMessage> response,
                                               std::exception_ptr error) {
                          py::gil_scoped_acquire gil;
                          if (error) {
                            (*held)(py::none(), exception_object(error));
                            return;
                          }
                          (*held)(to_python(received(response_class, std::move(*response))),
                                  py::none());
                        });
    }
    return py::make_tuple(id.client, id.sequence);
  }

  bool forget(std::uint32_t client, std::uint64_t sequence) {
    return client_.forget(RequestId{client, sequence});
  }
  std::size_t prune() { return client_.prune_pending(); }
  std::size_t pending() const { return client_.pending(); }
  bool ready() const {
    py::gil_scoped_release release;
    return client_.service_is_ready();
  }
  bool wait(const py::object& timeout_sec) const {
    const std::chrono::nanoseconds timeout = timeout_of(timeout_sec);
    py::gil_scoped_release release;
    return client_.wait_for_service(timeout);
  }
  const std::string& name() const { return client_.service_name(); }

 private:
  const MessageClass* request_;
  const MessageClass* response_;
  SchemaClient client_;
};

// The Python log handler (agnocast/__init__.py passes logging's), touched
// with the GIL held; the library's lines reach it through the forwarder.
py::object& python_log_handler() {
  static auto* handler = new py::object;
  return *handler;
}

LogForwarder& log_forwarder() {
  static auto* forwarder = new LogForwarder([](std::vector<LogLine>& lines) {
    // While the interpreter goes away the lines are lost, as it cannot run them.
    if (!Py_IsInitialized() || _Py_IsFinalizing()) return;
    py::gil_scoped_acquire gil;
    const py::object handler = python_log_handler();
    if (!handler || handler.is_none()) return;
    for (const LogLine& line : lines) {
      try {
        handler(static_cast<int>(line.level), decode(line.text));
      } catch (py::error_already_set& e) {
        e.discard_as_unraisable("agnocast log handler");
      }
    }
  });
  return *forwarder;
}

std::chrono::nanoseconds seconds(double value) {
  if (!(value > 0)) throw py::value_error("agnocast: the period must be positive seconds");
  return std::chrono::nanoseconds(static_cast<std::int64_t>(value * 1e9));
}

// Runs an executor's wait with the GIL released, then lets Python see a
// SIGINT that arrived meanwhile (KeyboardInterrupt).
template <class F>
auto without_gil(F&& f) {
  {
    py::gil_scoped_release release;
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
    } else {
      auto result = f();
      py::gil_scoped_acquire again;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      return result;
    }
  }
  if constexpr (std::is_void_v<decltype(f())>) {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

}  // namespace
}  // namespace agnocast::python

PYBIND11_MODULE(_core, m) {
  using namespace agnocast;
  using namespace agnocast::python;
  m.doc() = "agnocast zero-copy publish/subscribe (the compiled core of the agnocast package)";

  // Exceptions: named as the library's, most general first.
  static py::exception<Error> error(m, "Error");
  static py::exception<DeviceError> device_error(m, "DeviceError", error.ptr());
  static py::exception<AccessDenied> access_denied(m, "AccessDenied", device_error.ptr());
  static py::exception<TypeMismatch> type_mismatch(m, "TypeMismatch", device_error.ptr());
  static py::exception<ModuleNotLoaded> module_not_loaded(m, "ModuleNotLoaded", error.ptr());
  static py::exception<VersionMismatch> version_mismatch(m, "VersionMismatch", error.ptr());
  static py::exception<QueueError> queue_error(m, "QueueError", error.ptr());
  static py::exception<TopicWithoutSchema> no_schema(m, "TopicWithoutSchema", error.ptr());
  static py::exception<SchemaError> schema_error(m, "SchemaError", error.ptr());
  static py::exception<InvalidMessage> invalid_message(m, "InvalidMessage", error.ptr());
  static py::exception<PoolExhausted> pool_exhausted(m, "PoolExhausted", error.ptr());
  static py::exception<MessagePublished> message_published(m, "MessagePublished", error.ptr());
  static py::exception<ReadOnlyMessage> read_only(m, "ReadOnlyMessage", error.ptr());
  static py::exception<ServiceExists> service_exists(m, "ServiceExists", error.ptr());
  static py::exception<ServiceUnavailable> service_unavailable(m, "ServiceUnavailable",
                                                               error.ptr());
  static py::exception<RequestRejected> request_rejected(m, "RequestRejected", error.ptr());
  static py::exception<TooManyRequests> too_many_requests(m, "TooManyRequests", error.ptr());
  invalid_message_type() = invalid_message;
  // Tried last registered first: derived classes before their bases.
  py::register_exception_translator([](std::exception_ptr failure) {
    try {
      if (failure) std::rethrow_exception(failure);
    } catch (const AccessDenied& e) {
      access_denied(e.what());
    } catch (const TypeMismatch& e) {
      type_mismatch(e.what());
    } catch (const DeviceError& e) {
      device_error(e.what());
    } catch (const ModuleNotLoaded& e) {
      module_not_loaded(e.what());
    } catch (const VersionMismatch& e) {
      version_mismatch(e.what());
    } catch (const QueueError& e) {
      queue_error(e.what());
    } catch (const TopicWithoutSchema& e) {
      no_schema(e.what());
    } catch (const MessagePublished& e) {
      message_published(e.what());
    } catch (const ReadOnlyMessage& e) {
      read_only(e.what());
    } catch (const InvalidMessage& e) {
      invalid_message(e.what());
    } catch (const ServiceExists& e) {
      service_exists(e.what());
    } catch (const ServiceUnavailable& e) {
      service_unavailable(e.what());
    } catch (const RequestRejected& e) {
      request_rejected(e.what());
    } catch (const TooManyRequests& e) {
      too_many_requests(e.what());
    } catch (const Error& e) {
      error(e.what());
    } catch (const SchemaError& e) {
      schema_error(e.what());
    } catch (const PoolExhausted& e) {
      pool_exhausted(e.what());
    }
  });

  py::class_<QoS>(m, "QoS")
      .def(py::init([](std::size_t depth, bool transient_local) {
             QoS qos(depth);
             if (transient_local) qos.transient_local();
             return qos;
           }),
           py::arg("depth"), py::arg("transient_local") = false)
      .def_property_readonly("depth", &QoS::depth)
      .def_property_readonly("transient_local", &QoS::is_transient_local)
      .def("__repr__", [](const QoS& qos) {
        return "QoS(depth=" + std::to_string(qos.depth()) +
               (qos.is_transient_local() ? ", transient_local=True)" : ")");
      });

  py::class_<MessageClass, std::unique_ptr<MessageClass, py::nodelete>>(m, "MessageType")
      .def(py::init([](py::bytes blob, py::bytes defaults) {
             return const_cast<MessageClass*>(message_class(blob, defaults));
           }),
           py::arg("schema"), py::arg("defaults") = py::bytes())
      .def_property_readonly("type_name", [](const MessageClass& c) { return c.type().name; })
      .def("new_message", [](const MessageClass& c) { return py::cast(new_loan(&c)); })
      .def("__repr__",
           [](const MessageClass& c) { return "<agnocast message type " + c.type().name + ">"; })
      .def_property_readonly("type_hash", [](const MessageClass& c) { return c.type().hash; })
      .def_property_readonly("size", [](const MessageClass& c) { return c.type().size; })
      .def_property_readonly("align", [](const MessageClass& c) { return c.type().align; })
      .def_property_readonly("schema",
                             [](const MessageClass& c) {
                               const auto blob = c.schema.blob();
                               return py::bytes(reinterpret_cast<const char*>(blob.data()),
                                                blob.size());
                             })
      .def_property_readonly("definition",
                             [](const MessageClass& c) {
                               // Another program's text: a byte that is not UTF-8 must not raise.
                               const std::string text = ros2msg_definition(c.schema.schema());
                               PyObject* decoded = PyUnicode_DecodeUTF8(
                                   text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
                               if (decoded == nullptr) throw py::error_already_set();
                               return py::reinterpret_steal<py::str>(decoded);
                             })
      .def_property_readonly("fields",
                             [](const MessageClass& c) {
                               py::list names;
                               for (const SchemaField& field : c.type().fields)
                                 names.append(field.name);
                               return names;
                             })
      .def("layout", [](const MessageClass& c) {
        // Every type's fields as (type, field, offset, size, element_size, element_align).
        py::list out;
        for (const SchemaType& type : c.schema.schema().types) {
          out.append(py::make_tuple(type.name, "", 0, type.size, type.size, type.align));
          for (const SchemaField& f : type.fields) {
            out.append(py::make_tuple(type.name, f.name, f.offset, f.size, f.element_size,
                                      f.element_align));
          }
        }
        return out;
      });

  py::class_<Keeper>(m, "_Keeper");

  // The base of the message classes (agnocast.Message in _message.py); its
  // constructor only takes another core message, whose memory it shares.
  py::class_<Message>(m, "Message")
      .def(py::init([](const Message& memory) { return memory; }), py::arg("memory"))
      .def("__getattr__", &Message::get)
      .def("__setattr__", &Message::set)
      .def("__dir__",
           [](const Message& msg) {
             py::list names;
             for (const SchemaField& field : msg.type().fields) names.append(field.name);
             return names;
           })
      .def_property_readonly("_type_name", [](const Message& msg) { return msg.type().name; })
      .def_property_readonly("_type_hash", [](const Message& msg) { return msg.type().hash; })
      .def_property_readonly("_fields",
                             [](const Message& msg) {
                               py::list names;
                               for (const SchemaField& f : msg.type().fields) names.append(f.name);
                               return names;
                             })
      .def_property_readonly("_writable", &Message::writable)
      .def_property_readonly("_published",
                             [](const Message& msg) { return msg.storage->published; })
      .def_property_readonly("_address",
                             [](const Message& msg) {
                               msg.storage->check();
                               return reinterpret_cast<std::uintptr_t>(msg.base);
                             })
      .def("__repr__", [](const Message& msg) {
        if (msg.storage->published) return "<" + msg.type().name + " (published)>";
        std::string out = msg.type().name + "(";
        bool first = true;
        for (const SchemaField& field : msg.type().fields) {
          if (!first) out += ", ";
          first = false;
          out += field.name + "=" +
                 py::repr(field_value(msg.storage, msg.base, field)).cast<std::string>();
        }
        return out + ")";
      });

  core_message_init() = m.attr("Message").attr("__init__");

  py::class_<Sequence> sequence_class(m, "Sequence", py::buffer_protocol());
  sequence_class.def("__len__", &Sequence::length)
      .def("resize", &Sequence::resize, py::arg("count"))
      .def_property_readonly("_writable", &Sequence::writable)
      .def("__getitem__",
           [](const Sequence& s, std::ptrdiff_t i) -> py::object {
             std::byte* at = s.element(i);
             if (s.field->kind == FieldKind::String)
               return decode(s.ops().string_at(at, *s.field, s.storage->memory));
             if (s.field->kind == FieldKind::Message) {
               return to_python(Message{s.storage, at, s.field->nested});
             }
             return read_number(at, s.field->kind);
           })
      .def("__getitem__",
           [](const Sequence& s, py::slice slice) -> py::object {
             if (is_primitive(s.field->kind)) {
               const VectorSpan span = s.elements();
               return number_view(s.storage, span.data, s.field->kind, span.count)[slice];
             }
             py::list all;
             for (std::size_t i = 0; i < s.length(); ++i) {
               all.append(py::cast(s).attr("__getitem__")(i));
             }
             return all[slice];
           })
      .def("__setitem__",
           [](const Sequence& s, std::ptrdiff_t i, py::handle value) {
             if (!s.writable()) throw ReadOnlyMessage("agnocast: a received message is read-only");
             std::byte* at = s.element(i);
             if (s.field->kind == FieldKind::String) {
               write_string(s.ops(), at, value, *s.field);
             } else if (s.field->kind == FieldKind::Message) {
               const auto& source = py::cast<const Message&>(value);
               source.storage->check();
               if (source.type().hash != s.storage->cls->schema.type(s.field->nested).hash) {
                 throw py::type_error("agnocast: the element has another type");
               }
               source.storage->cls->ops.copy(at, source.base, source.index, source.storage->memory);
             } else {
               write_number(at, s.field->kind, value, s.field->name);
             }
           })
      .def(
          "__array__",
          [](const Sequence& s, py::object dtype) -> py::object {
            if (!is_primitive(s.field->kind)) {
              throw py::type_error("agnocast: only fields of numbers are numpy arrays");
            }
            const VectorSpan span = s.elements();
            py::object view = number_view(s.storage, span.data, s.field->kind, span.count);
            if (!dtype.is_none()) return view.attr("astype")(dtype, py::arg("copy") = false);
            return view;
          },
          py::arg("dtype") = py::none())
      .def("__repr__", [](const Sequence& s) {
        if (is_primitive(s.field->kind)) {
          const VectorSpan span = s.elements();
          return "Sequence(" +
                 py::repr(number_view(s.storage, span.data, s.field->kind, span.count))
                     .cast<std::string>() +
                 ")";
        }
        return "Sequence(" + std::to_string(s.length()) + " elements)";
      });

  // pybind11's buffer getter may not throw; this one raises instead.
  auto* sequence_type = reinterpret_cast<PyHeapTypeObject*>(sequence_class.ptr());
  sequence_type->as_buffer.bf_getbuffer = sequence_getbuffer;
  sequence_type->as_buffer.bf_releasebuffer = sequence_releasebuffer;

  py::enum_<CallbackGroupType>(m, "CallbackGroupType")
      .value("MutuallyExclusive", CallbackGroupType::MutuallyExclusive)
      .value("Reentrant", CallbackGroupType::Reentrant);
  py::class_<CallbackGroup, std::shared_ptr<CallbackGroup>>(m, "CallbackGroup")
      .def(py::init<CallbackGroupType>(), py::arg("type"))
      .def_property_readonly("type", &CallbackGroup::type);

  py::class_<Node, std::shared_ptr<Node>>(m, "Node")
      .def(py::init<std::string>(), py::arg("name"))
      .def("get_name", &Node::get_name)
      .def("create_callback_group", &Node::create_callback_group, py::arg("type"))
      .def_property_readonly("default_callback_group", &Node::get_default_callback_group);

  py::class_<PyPublisher, std::shared_ptr<PyPublisher>>(m, "Publisher")
      .def(py::init([](const Node& node, const MessageClass& cls, const std::string& topic,
                       const QoS& qos) {
             py::gil_scoped_release release;
             return std::make_shared<PyPublisher>(node, &cls, topic, qos);
           }),
           py::arg("node"), py::arg("type"), py::arg("topic"), py::arg("qos"))
      .def("borrow_loaned_message", &PyPublisher::borrow)
      .def("publish", &PyPublisher::publish, py::arg("message"))
      .def("get_subscription_count", &PyPublisher::subscription_count)
      .def("wait_for_subscribers", &PyPublisher::wait_for_subscribers, py::arg("count"),
           py::arg("timeout"))
      .def_property_readonly("topic_name", &PyPublisher::topic);

  py::class_<PySubscription, std::shared_ptr<PySubscription>>(m, "Subscription")
      .def(py::init([](const Node& node, const MessageClass& cls, const std::string& topic,
                       const QoS& qos, py::object callback, bool ignore_local,
                       std::shared_ptr<CallbackGroup> group) {
             SubscriptionOptions options;
             options.ignore_local_publications = ignore_local;
             options.callback_group = detail::group_or_default(*node.state(), std::move(group));
             Callback held(std::move(callback));
             std::shared_ptr<PySubscription> subscription;
             {
               py::gil_scoped_release release;
               subscription =
                   std::make_shared<PySubscription>(node, &cls, topic, qos, held, options);
               detail::register_waitable(*node.state(), subscription);
             }
             return subscription;
           }),
           py::arg("node"), py::arg("type"), py::arg("topic"), py::arg("qos"), py::arg("callback"),
           py::arg("ignore_local_publications") = false, py::arg("callback_group") = nullptr)
      .def("get_publisher_count", &PySubscription::publisher_count)
      .def_property_readonly("topic_name", &PySubscription::topic);

  py::class_<PyPolling, std::shared_ptr<PyPolling>>(m, "PollingSubscriber")
      .def(py::init([](const Node& node, const MessageClass& cls, const std::string& topic,
                       const QoS& qos, bool ignore_local) {
             SubscriptionOptions options;
             options.ignore_local_publications = ignore_local;
             py::gil_scoped_release release;
             return std::make_shared<PyPolling>(node, &cls, topic, qos, options);
           }),
           py::arg("node"), py::arg("type"), py::arg("topic"), py::arg("qos"),
           py::arg("ignore_local_publications") = false)
      .def("take_data", [](PyPolling& p) { return p.take(false); })
      .def("take_new_data", [](PyPolling& p) { return p.take(true); })
      .def("get_publisher_count", &PyPolling::publisher_count)
      .def_property_readonly("topic_name", &PyPolling::topic);

  py::class_<PyService, std::shared_ptr<PyService>>(m, "Service")
      .def(py::init([](Node& node, const MessageClass& request, const MessageClass& response,
                       const std::string& name, const QoS& qos, py::object callback,
                       std::shared_ptr<CallbackGroup> group) {
             Callback held(std::move(callback));
             py::gil_scoped_release release;
             return std::make_shared<PyService>(node, &request, &response, name, qos, held,
                                                std::move(group));
           }),
           py::arg("node"), py::arg("request_type"), py::arg("response_type"), py::arg("name"),
           py::arg("qos"), py::arg("callback"), py::arg("callback_group") = nullptr)
      .def_property_readonly("service_name", &PyService::name);

  py::class_<PyClient, std::shared_ptr<PyClient>>(m, "Client")
      .def(py::init([](Node& node, const MessageClass& request, const MessageClass& response,
                       const std::string& name, const QoS& qos,
                       std::shared_ptr<CallbackGroup> group) {
             py::gil_scoped_release release;
             return std::make_shared<PyClient>(node, &request, &response, name, qos,
                                               std::move(group));
           }),
           py::arg("node"), py::arg("request_type"), py::arg("response_type"), py::arg("name"),
           py::arg("qos"), py::arg("callback_group") = nullptr)
      .def("borrow_loaned_request", &PyClient::borrow)
      .def("_call", &PyClient::call, py::arg("request"), py::arg("timeout_sec"))
      .def("_send", &PyClient::send, py::arg("request"), py::arg("done"))
      .def("_forget", &PyClient::forget, py::arg("client"), py::arg("sequence"))
      .def("_pending", &PyClient::pending)
      .def("prune_pending_requests", &PyClient::prune)
      .def("service_is_ready", &PyClient::ready)
      .def("wait_for_service", &PyClient::wait, py::arg("timeout_sec") = py::none())
      .def_property_readonly("service_name", &PyClient::name);

  py::class_<Timer, std::shared_ptr<Timer>>(m, "Timer")
      .def(py::init([](Node& node, double period, py::object callback,
                       std::shared_ptr<CallbackGroup> group) {
             Callback held(std::move(callback));
             auto run = [held] {
               py::gil_scoped_acquire gil;
               (*held)();
             };
             const auto interval = seconds(period);
             py::gil_scoped_release release;
             return node.create_wall_timer(interval, std::move(run), std::move(group));
           }),
           py::arg("node"), py::arg("period"), py::arg("callback"),
           py::arg("callback_group") = nullptr)
      .def("cancel", &Timer::cancel)
      .def("reset", &Timer::reset)
      .def("is_canceled", &Timer::is_canceled)
      .def_property_readonly(
          "period", [](const Timer& t) { return static_cast<double>(t.period().count()) * 1e-9; });

  py::class_<Executor>(m, "Executor")
      // Without the GIL, as every call that may wait for a lock of the library:
      // the executor's threads take the GIL to run callbacks.
      .def("add_node", &Executor::add_node, py::arg("node"), py::keep_alive<1, 2>(),
           py::call_guard<py::gil_scoped_release>())
      .def("remove_node", &Executor::remove_node, py::arg("node"),
           py::call_guard<py::gil_scoped_release>())
      .def("spin", [](Executor& e) { without_gil([&] { e.spin(); }); })
      .def("spin_some", [](Executor& e) { without_gil([&] { e.spin_some(); }); })
      .def(
          "spin_once",
          [](Executor& e, double timeout) {
            return without_gil([&] {
              return e.spin_once(
                  std::chrono::milliseconds(static_cast<std::int64_t>(timeout * 1e3)));
            });
          },
          py::arg("timeout_sec") = 0.0)
      .def("cancel", [](Executor& e) { e.cancel(); });
  py::class_<SingleThreadedExecutor, Executor>(m, "SingleThreadedExecutor").def(py::init<>());
  py::class_<MultiThreadedExecutor, Executor>(m, "MultiThreadedExecutor")
      .def(py::init<std::size_t>(), py::arg("num_threads") = 0);

  m.def(
      "register_class",
      [](std::uint64_t hash, py::object cls) { python_classes()[hash] = std::move(cls); },
      py::arg("type_hash"), py::arg("cls"));
  m.def(
      "registered_class",
      [](std::uint64_t hash) -> py::object {
        const auto found = python_classes().find(hash);
        return found == python_classes().end() ? py::none() : found->second;
      },
      py::arg("type_hash"));

  // handler(level, text) gets the library's lines from a thread of the
  // forwarder (log_forwarder.hpp); None: back to stderr, once every line
  // waiting was handed over.
  m.def("set_log_handler", [](py::object handler) {
    if (handler.is_none()) {
      set_log_handler(nullptr);
      {
        py::gil_scoped_release release;  // the forwarder's thread may wait for the GIL
        log_forwarder().stop();
      }
      python_log_handler() = py::none();
      return;
    }
    python_log_handler() = std::move(handler);
    set_log_handler(
        [](LogLevel level, std::string_view text) { log_forwarder().post(level, text); });
  });
  m.attr("SERVICE_QUEUE_DEPTH_DEFAULT") = service_queue_depth_default;
  m.attr("CLIENT_IN_FLIGHT_DEFAULT") = client_in_flight_default;
  m.attr("LOG_DEBUG") = static_cast<int>(LogLevel::debug);
  m.attr("LOG_INFO") = static_cast<int>(LogLevel::info);
  m.attr("LOG_WARNING") = static_cast<int>(LogLevel::warning);
  m.attr("LOG_ERROR") = static_cast<int>(LogLevel::error);
}
