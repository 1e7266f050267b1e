#include "test_support.hpp"

#include <agnocast/cdr.hpp>
#include <cstring>
#include <new>
#include <stdexcept>

#include "kernel/runtime.hpp"

namespace standard_messages_test {
namespace {

using agnocast::FieldKind;
using agnocast::FieldShape;

class SampleWriter {
 public:
  SampleWriter(const agnocast::Schema& schema, std::uint32_t seed)
      : schema_(schema), next_(seed * 1000 + 1) {
    out_.assign(agnocast::cdr::encapsulation_header.begin(),
                agnocast::cdr::encapsulation_header.end());
  }

  std::vector<std::uint8_t> message() {
    write_type(0);
    return std::move(out_);
  }

 private:
  void write_type(std::uint16_t index) {
    for (const agnocast::SchemaField& field : schema_.types.at(index).fields) write_field(field);
  }

  void write_field(const agnocast::SchemaField& field) {
    std::uint32_t count = 1;
    if (field.shape == FieldShape::Array) count = field.array_length;
    if (field.shape == FieldShape::Sequence) {
      if (field.sequence_bound != 0) {
        count = field.sequence_bound <= 16 ? field.sequence_bound : 2;
      } else {
        count = 1 + next_ % 3;
      }
      put<std::uint32_t>(count);
    }
    for (std::uint32_t i = 0; i < count; ++i) write_element(field);
  }

  void write_element(const agnocast::SchemaField& field) {
    const std::uint32_t n = next_++;
    // Signed kinds alternate in sign; every number is non-zero.
    const bool negative = n % 2 == 1;
    switch (field.kind) {
      case FieldKind::Bool:
        return put<std::uint8_t>(1);
      case FieldKind::Int8:
        return put(static_cast<std::int8_t>(negative ? -static_cast<int>(1 + n % 100)
                                                     : static_cast<int>(1 + n % 100)));
      case FieldKind::UInt8:
        return put(static_cast<std::uint8_t>(1 + n % 200));
      case FieldKind::Int16:
        return put(static_cast<std::int16_t>(negative ? -static_cast<int>(1 + n % 30000)
                                                      : static_cast<int>(1 + n % 30000)));
      case FieldKind::UInt16:
        return put(static_cast<std::uint16_t>(1 + n % 60000));
      case FieldKind::Int32:
        return put(negative ? -static_cast<std::int32_t>(n) * 7 : static_cast<std::int32_t>(n) * 7);
      case FieldKind::UInt32:
        return put(n * 11);
      case FieldKind::Int64:  // beyond 32 bits
        return put(static_cast<std::int64_t>(n) *
                   (negative ? -(std::int64_t{1} << 33) : std::int64_t{1} << 33));
      case FieldKind::UInt64:
        return put((static_cast<std::uint64_t>(n) << 35) | 5);
      case FieldKind::Float32:
        return put(static_cast<float>(n) * 0.25F + 0.5F);
      case FieldKind::Float64:
        return put(static_cast<double>(n) * -0.125 - 0.75);
      case FieldKind::String: {
        const std::uint32_t length =
            field.string_bound != 0 && field.string_bound <= 32 ? field.string_bound : 1 + n % 5;
        put<std::uint32_t>(length + 1);
        for (std::uint32_t i = 0; i < length; ++i) {
          out_.push_back(static_cast<std::uint8_t>('a' + (n + i) % 26));
        }
        out_.push_back(0);
        return;
      }
      case FieldKind::Message:
        return write_type(field.nested);
      case FieldKind::Opaque:
        break;
    }
    throw std::invalid_argument("sample_cdr: field " + field.name + " has no CDR form");
  }

  // Aligned to its size relative to the payload, after the encapsulation header.
  template <class T>
  void put(T value) {
    const std::size_t payload = out_.size() - agnocast::cdr::encapsulation_header.size();
    out_.resize(out_.size() + (sizeof(T) - payload % sizeof(T)) % sizeof(T), 0);
    const std::size_t at = out_.size();
    out_.resize(at + sizeof(T));
    std::memcpy(out_.data() + at, &value, sizeof(T));
  }

  const agnocast::Schema& schema_;
  std::uint32_t next_;
  std::vector<std::uint8_t> out_;
};

}  // namespace

void install_test_runtime() {
  static const bool installed = [] {
    static constexpr std::size_t pool_size = 4 << 20;
    // Left to the test runtime for the whole process.
    auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
    agnocast::detail::Runtime::install_for_testing(region, pool_size);
    return true;
  }();
  (void)installed;
}

std::vector<std::uint8_t> sample_cdr(const agnocast::Schema& schema, std::uint32_t seed) {
  return SampleWriter(schema, seed).message();
}

}  // namespace standard_messages_test
