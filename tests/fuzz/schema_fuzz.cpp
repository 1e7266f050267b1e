// The schema blob as the kernel hands it to a reader (any endpoint's process
// wrote it): parse_schema accepts only what its readers can trust, and what
// it accepts has a definition text.
#include <cstddef>
#include <cstdint>
#include <span>

#include "agnocast/cdr.hpp"
#include "agnocast/schema.hpp"
#include "agnocast/schema_definition.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  agnocast::Schema schema;
  try {
    schema = agnocast::parse_schema(std::span<const std::uint8_t>(data, size));
  } catch (const agnocast::SchemaError&) {
    return 0;
  }
  try {
    agnocast::ros2msg_definition(schema);
  } catch (const agnocast::cdr::Error&) {  // raw or opaque types have no .msg form
  }
  return 0;
}
