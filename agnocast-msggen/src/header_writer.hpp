// The C++ header for one message: the struct, its traits and its XCDR1 code;
// for one service: those of its request and response, and the service type.
#pragma once

#include <string>
#include <string_view>

#include "message_spec.hpp"

namespace msggen {

// "PointCloud2" -> "point_cloud2", as ROS 2 names the header of a message.
std::string snake_case(std::string_view type_name);

// "<package>/msg/<snake_case>.hpp", the include path of a message's header.
std::string header_path(const std::string& package, const std::string& name);

// "<package>/srv/<snake_case>.hpp", the include path of a service's header.
std::string service_header_path(const std::string& package, const std::string& name);

std::string write_header(const MessageSpec& spec);
std::string write_service_header(const ServiceSpec& spec);

}  // namespace msggen
