#include "agnocast/schema_service_types.hpp"

#include <utility>

#include "agnocast/errors.hpp"
#include "agnocast/naming.hpp"

namespace agnocast {
namespace {

constexpr std::string_view request_suffix = "_Request";
constexpr std::string_view response_suffix = "_Response";

// "pkg/srv/Name" from a part's type name, empty when it has not the suffix.
std::string_view without_suffix(std::string_view type, std::string_view suffix) {
  if (!type.ends_with(suffix)) return {};
  return type.substr(0, type.size() - suffix.size());
}

}  // namespace

std::string service_type_name(const ServiceTypes& types) {
  const std::string_view request = without_suffix(types.request.type_name, request_suffix);
  const std::string_view response = without_suffix(types.response.type_name, response_suffix);
  if (request.empty() || request != response) return {};
  return normalized_service_type(request);
}

std::string normalized_service_type(std::string_view type) {
  const std::size_t first = type.find('/');
  if (first == std::string_view::npos || first == 0) return {};
  const std::size_t second = type.find('/', first + 1);
  if (second == std::string_view::npos) {
    const std::string_view name = type.substr(first + 1);
    if (name.empty()) return {};
    return std::string(type.substr(0, first)) + "/srv/" + std::string(name);
  }
  const bool three_parts = type.find('/', second + 1) == std::string_view::npos;
  if (!three_parts || type.substr(first + 1, second - first - 1) != "srv" ||
      second + 1 == type.size()) {
    return {};
  }
  return std::string(type);
}

std::optional<ServiceTypes> find_service_types(std::string_view service) {
  validate_service_name(service);
  std::optional<SchemaTopic> request = find_schema_topic(service_request_topic(service));
  if (!request) return std::nullopt;
  std::optional<SchemaTopic> response = find_schema_topic(service_reply_topic(service));
  if (!response) return std::nullopt;
  return ServiceTypes{std::move(*request), std::move(*response)};
}

void require_service_type(const ServiceTypes& types, std::string_view service,
                          std::string_view type) {
  const std::string wanted = normalized_service_type(type);
  const std::string found = service_type_name(types);
  if (!wanted.empty() && wanted == found) return;
  const std::string serves =
      found.empty() ? "the parts " + types.request.type_name + " and " + types.response.type_name
                    : "type " + found;
  throw TypeMismatch("agnocast: service " + std::string(service) + " has " + serves + ", not " +
                     (wanted.empty() ? std::string(type) : wanted) +
                     "; `agnocast-cli service type " + std::string(service) + "` shows it");
}

}  // namespace agnocast
