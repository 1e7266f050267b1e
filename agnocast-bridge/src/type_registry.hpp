// The message and service types a bridge binary knows, by ROS 2 type name.
// The standard set is added by the agnocast-bridge binary;
// agnocast_add_bridge() (CMake) builds a bridge that adds a user's generated
// packages as well.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/message_traits.hpp"
#include "agnocast/service_traits.hpp"
#include "relay.hpp"
#include "service_relay.hpp"

namespace agnocast_bridge {

class TypeRegistry {
 public:
  using MakeRelay = std::function<std::unique_ptr<Relay>(const RelayContext&)>;

  template <class T>
  void add() {
    const std::string name(agnocast::message_traits<T>::type_name);
    entries_[name] = Entry{[](const RelayContext& context) -> std::unique_ptr<Relay> {
                             return std::make_unique<ToDds<T>>(context);
                           },
                           [](const RelayContext& context) -> std::unique_ptr<Relay> {
                             return std::make_unique<FromDds<T>>(context);
                           }};
  }

  template <agnocast::ServiceType Srv>
  void add_service() {
    const std::string name(agnocast::service_traits<Srv>::type_name);
    services_[name] =
        ServiceEntry{[](const ServiceRelayContext& context) -> std::unique_ptr<Relay> {
                       return std::make_unique<ServiceToDds<Srv>>(context);
                     },
                     [](const ServiceRelayContext& context) -> std::unique_ptr<Relay> {
                       return std::make_unique<ServiceFromDds<Srv>>(context);
                     }};
  }

  bool knows(std::string_view type_name) const;
  // Throws std::out_of_range for a type it does not know.
  std::unique_ptr<Relay> make(std::string_view type_name, Direction direction,
                              const RelayContext& context) const;
  std::vector<std::string> type_names() const;

  bool knows_service(std::string_view type_name) const;
  // Throws std::out_of_range for a service type it does not know.
  std::unique_ptr<Relay> make_service(std::string_view type_name, Direction direction,
                                      const ServiceRelayContext& context) const;
  std::vector<std::string> service_type_names() const;

 private:
  using MakeServiceRelay = std::function<std::unique_ptr<Relay>(const ServiceRelayContext&)>;
  struct Entry {
    MakeRelay to_dds;
    MakeRelay from_dds;
  };
  struct ServiceEntry {
    MakeServiceRelay to_dds;
    MakeServiceRelay from_dds;
  };
  std::map<std::string, Entry, std::less<>> entries_;
  std::map<std::string, ServiceEntry, std::less<>> services_;
};

}  // namespace agnocast_bridge
