// The message type a ros2msg definition describes (the text an MCAP file's
// schema holds: the type's .msg, then each type it uses after a line of 80 '='
// and "MSG: pkg/Name"), laid out as agnocast-msggen lays out the C++ it
// generates: fields in order, each at its natural alignment, agnocast::vector
// and agnocast::string as this standard library builds them, and an empty
// message holding one byte. Its schema and type hash are therefore those of
// the generated type, so `bag play` can publish a file's type that no
// program has registered yet, and subscribers compiled from the same .msg
// files accept it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace agnocast::cli {

struct DefinitionType {
  std::string type_name;  // "pkg/msg/Name"
  std::uint64_t type_hash = 0;
  std::vector<std::uint8_t> schema;  // the blob, as the generated type's schema_of<T>()
};

// `schema_name` as an MCAP schema names it ("pkg/msg/Name" or "pkg/Name").
// Throws InputError saying which type or line of the definition is wrong.
DefinitionType type_from_definition(std::string_view schema_name, std::string_view definition);

}  // namespace agnocast::cli
