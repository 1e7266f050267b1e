// The .msg text, constants and comments included, of every message type in
// the standard set shipped in messages/, compiled in: tools that write a
// type's definition for others (agnocast-cli bag record) give the whole
// file, as rosbag2 does, where the schema registered in the kernel holds
// only the fields.
#pragma once

#include <string_view>

namespace agnocast {

// The text of "pkg/msg/Name" (or "pkg/Name"), or nullptr for a type not in the set.
const std::string_view* standard_msg_text(std::string_view type_name);

}  // namespace agnocast
