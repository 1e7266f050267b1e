// A message type's definition in the text form ROS 2 tools exchange: the
// .msg files of the type and of every type it uses, joined as rosbag2 joins
// them in MCAP files (schema encoding "ros2msg") and Foxglove reads them.
// Each type's text is the one agnocast-msggen read, carried in the schema.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "agnocast/schema.hpp"

namespace agnocast {

// "pkg/msg/Name" as .msg files name it: "pkg/Name".
std::string ros2msg_type_name(std::string_view type_name);

// The type's definition as rosbag2 writes it: its own .msg text, then for
// each type it uses (depth first, once each) a line of 80 '=', "MSG: pkg/Name"
// and that type's text. Each text is the schema's (the .msg file, constants
// and comments included) when its fields are the type's, by name and in
// order; else, or when the schema has none (a type declared in C++), the
// type's fields written from the schema. Throws cdr::Error (<agnocast/cdr.hpp>)
// for a type without field descriptions (raw or opaque bytes have no .msg form).
std::string ros2msg_definition(const Schema& schema);

// The field names of a .msg text, in order (constants and comments skipped).
std::vector<std::string> msg_text_field_names(std::string_view text);

}  // namespace agnocast
