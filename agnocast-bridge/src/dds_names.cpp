#include "dds_names.hpp"

#include <stdexcept>

namespace agnocast_bridge {

namespace {

std::string_view without_leading_slash(std::string_view name) {
  if (name.starts_with('/')) name.remove_prefix(1);
  return name;
}

}  // namespace

std::string dds_topic_name(std::string_view agnocast_topic) {
  return "rt/" + std::string(without_leading_slash(agnocast_topic));
}

DdsServiceTopics dds_service_topic_names(std::string_view agnocast_service) {
  const std::string name(without_leading_slash(agnocast_service));
  return {"rq/" + name + "Request", "rr/" + name + "Reply"};
}

ServiceTypeNames dds_service_type_names(std::string_view ros_service_type) {
  const auto first = ros_service_type.find('/');
  constexpr std::string_view kind = "/srv/";
  if (first == std::string_view::npos || ros_service_type.substr(first, kind.size()) != kind ||
      ros_service_type.size() == first + kind.size()) {
    throw std::invalid_argument("not a service type name of the form pkg/srv/Name: '" +
                                std::string(ros_service_type) + "'");
  }
  const std::string request = std::string(ros_service_type) + "_Request";
  const std::string response = std::string(ros_service_type) + "_Response";
  // dds_type_name checks the rest of the form.
  return {request, response, dds_type_name(request), dds_type_name(response)};
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
