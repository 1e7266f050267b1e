#include "dds_names.hpp"

#include <stdexcept>

namespace agnocast_bridge {

std::string dds_topic_name(std::string_view agnocast_topic) {
  if (agnocast_topic.starts_with('/')) agnocast_topic.remove_prefix(1);
  return "rt/" + std::string(agnocast_topic);
}

std::string dds_type_name(std::string_view ros_type_name) {
  const auto first = ros_type_name.find('/');
  const auto last = ros_type_name.rfind('/');
  if (first == std::string_view::npos || first == 0 || last == first ||
      last + 1 == ros_type_name.size() || ros_type_name.find('/', first + 1) != last) {
    throw std::invalid_argument("not a type name of the form pkg/msg/Type: '" +
                                std::string(ros_type_name) + "'");
  }
  const std::string_view package = ros_type_name.substr(0, first);
  const std::string_view kind = ros_type_name.substr(first + 1, last - first - 1);
  const std::string_view type = ros_type_name.substr(last + 1);
  return std::string(package) + "::" + std::string(kind) + "::dds_::" + std::string(type) + "_";
}

}  // namespace agnocast_bridge
