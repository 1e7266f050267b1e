// bag play's reading of a file's ros2msg definition: a laid-out type whose
// schema its readers accept, or an InputError, for any text.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "agnocast/schema.hpp"
#include "bag/definition_type.hpp"
#include "cli.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const agnocast::cli::DefinitionType type =
        agnocast::cli::type_from_definition("fuzz_msgs/msg/Fuzz", text);
    agnocast::parse_schema(type.schema);  // throws only if the builder made what readers refuse
  } catch (const agnocast::cli::InputError&) {
  }
  return 0;
}
