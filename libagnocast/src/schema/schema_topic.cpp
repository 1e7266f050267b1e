#include "agnocast/schema_topic.hpp"

#include <utility>

#include "agnocast/inspect.hpp"
#include "agnocast/schema_definition.hpp"

namespace agnocast {

std::string SchemaTopic::definition() const { return ros2msg_definition(schema); }

std::optional<SchemaTopic> find_schema_topic(std::string_view topic) {
  const std::string name(topic);
  const std::optional<TopicInfo> info = topic_info(name);
  if (!info) return std::nullopt;
  std::optional<std::vector<std::uint8_t>> blob = topic_schema(name);
  if (!blob || blob->empty()) {
    throw TopicWithoutSchema(
        "topic '" + name + "' (type " + info->type_name +
        ") has no schema: its endpoints were built with a type that does not describe its "
        "fields; declare it with AGNOCAST_MESSAGE or generate it with agnocast-msggen and "
        "rebuild the publisher");
  }
  SchemaTopic found;
  found.topic = name;
  found.type_name = info->type_name;
  found.type_hash = info->type_hash;
  found.blob = std::move(*blob);
  found.schema = parse_schema(found.blob);
  return found;
}

SchemaTopic resolve_schema_topic(std::string_view topic) {
  std::optional<SchemaTopic> found = find_schema_topic(topic);
  if (!found) {
    throw TopicWithoutSchema("no publisher or subscriber uses topic '" + std::string(topic) +
                             "', so its message type is unknown");
  }
  return std::move(*found);
}

}  // namespace agnocast
