#include "reload.hpp"

#include <spdlog/spdlog.h>

#include <exception>
#include <map>
#include <variant>

#include "agnocast/access_policy.hpp"
#include "agnocast/service_access.hpp"
#include "module_loader.hpp"
#include "mqueue_setup.hpp"

namespace agnocastd {
namespace {

std::string shown(const std::optional<std::string>& value) {
  return value ? "'" + *value + "'" : "unset";
}

void differences_in_parameters(const std::map<std::string, std::string>& in_force,
                               const std::map<std::string, std::string>& next,
                               std::vector<std::string>& lines) {
  const auto value_in = [](const auto& parameters, const std::string& name) {
    const auto found = parameters.find(name);
    return found == parameters.end() ? std::nullopt : std::optional(found->second);
  };
  std::map<std::string, bool> names;
  for (const auto& [name, value] : in_force) names[name] = true;
  for (const auto& [name, value] : next) names[name] = true;
  for (const auto& [name, unused] : names) {
    const auto old_value = value_in(in_force, name);
    const auto new_value = value_in(next, name);
    if (old_value != new_value) {
      lines.push_back("module_parameters." + name + " changed from " + shown(old_value) + " to " +
                      shown(new_value) +
                      ": the loaded module keeps its value until it is reloaded");
    }
  }
}

}  // namespace

void apply_access_policy(const std::optional<agnocast::AccessPolicy>& policy) {
  agnocast::set_access_policy(policy);
  if (policy) {
    // Counted as the config writes them: a services rule is two rules in the kernel.
    std::size_t service_rules = 0;
    const auto written = agnocast::written_access_rules(policy->rules);
    for (const agnocast::WrittenAccessRule& rule : written) {
      service_rules += std::holds_alternative<agnocast::ServiceAccessRule>(rule) ? 1 : 0;
    }
    spdlog::info("access policy in force: {} topics rule(s), {} services rule(s), default {}",
                 written.size() - service_rules, service_rules,
                 policy->default_allow ? "allow" : "deny");
  } else {
    spdlog::info("{}", agnocast::no_access_policy_meaning);
  }
}

std::vector<std::string> restart_only_differences(const Config& in_force, const Config& next) {
  std::vector<std::string> lines;
  differences_in_parameters(in_force.module_parameters, next.module_parameters, lines);
  if (in_force.module_path != next.module_path) {
    lines.push_back("module_path changed from " + shown(in_force.module_path) + " to " +
                    shown(next.module_path) + ": used only when agnocastd loads the module");
  }
  if (in_force.device_timeout != next.device_timeout) {
    lines.push_back("device_timeout_s changed: used only when agnocastd starts");
  }
  return lines;
}

void apply_runtime_config(const Config& in_force, const Config& next) {
  // Applied even when unchanged: the file, not whoever changed the system
  // since, says what is in force.
  apply_access_policy(next.access);
  try {
    apply_device_permissions(next.device);
    apply_mqueue_limits(next.mqueue);
  } catch (const std::exception&) {
    apply_access_policy(in_force.access);
    throw;
  }
  if (next.log_level != in_force.log_level) {
    spdlog::set_level(spdlog::level::from_str(next.log_level));
    spdlog::info("log level now {}", next.log_level);
  }
}

}  // namespace agnocastd
