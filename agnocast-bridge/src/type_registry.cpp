#include "type_registry.hpp"

#include <stdexcept>

namespace agnocast_bridge {

bool TypeRegistry::knows(std::string_view type_name) const {
  return entries_.find(type_name) != entries_.end();
}

std::unique_ptr<Relay> TypeRegistry::make(std::string_view type_name, Direction direction,
                                          const RelayContext& context) const {
  const auto entry = entries_.find(type_name);
  if (entry == entries_.end()) {
    throw std::out_of_range("no message type " + std::string(type_name));
  }
  return direction == Direction::to_dds ? entry->second.to_dds(context)
                                        : entry->second.from_dds(context);
}

std::vector<std::string> TypeRegistry::type_names() const {
  std::vector<std::string> names;
  for (const auto& [name, entry] : entries_) names.push_back(name);
  return names;
}

bool TypeRegistry::knows_service(std::string_view type_name) const {
  return services_.find(type_name) != services_.end();
}

std::unique_ptr<Relay> TypeRegistry::make_service(std::string_view type_name, Direction direction,
                                                  const ServiceRelayContext& context) const {
  const auto entry = services_.find(type_name);
  if (entry == services_.end()) {
    throw std::out_of_range("no service type " + std::string(type_name));
  }
  return direction == Direction::to_dds ? entry->second.to_dds(context)
                                        : entry->second.from_dds(context);
}

std::vector<std::string> TypeRegistry::service_type_names() const {
  std::vector<std::string> names;
  for (const auto& [name, entry] : services_) names.push_back(name);
  return names;
}

}  // namespace agnocast_bridge
