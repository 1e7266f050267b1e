// agnocast-cli policy show: the access policy the kernel enforces in this IPC
// namespace (agnocastd/README.md, "access"), its rules as agnocastd's config
// writes them (services rules included), user and group ids shown by name.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <string>
#include <variant>
#include <vector>

#include "agnocast/access_policy.hpp"
#include "agnocast/service_access.hpp"
#include "commands.hpp"
#include "table.hpp"

namespace agnocast::cli {
namespace {

using nlohmann::json;

std::string principal_text(InspectionSource& source, const AccessPrincipal& principal) {
  switch (principal.kind) {
    case AccessPrincipal::Kind::user:
      return "user:" + source.user_name(principal.id).value_or(std::to_string(principal.id));
    case AccessPrincipal::Kind::group:
      return "group:" + source.group_name(principal.id).value_or(std::to_string(principal.id));
    case AccessPrincipal::Kind::anyone:
      break;
  }
  return "*";
}

json principals_json(InspectionSource& source,
                     const std::optional<std::vector<AccessPrincipal>>& principals) {
  if (!principals) return nullptr;
  json list = json::array();
  for (const AccessPrincipal& principal : *principals) {
    list.push_back(principal_text(source, principal));
  }
  return list;
}

// A right's cell: who is listed, "(nobody)" for an empty list, or
// "(default)" when the rule leaves it to the default.
std::string right_cell(const json& principals) {
  if (principals.is_null()) return "(default)";
  if (principals.empty()) return "(nobody)";
  return cell(principals);
}

}  // namespace

json policy_show_json(InspectionSource& source) {
  const std::optional<AccessPolicy> policy = source.access_policy();
  if (!policy) return {{"policy", nullptr}};
  json rules = json::array();
  // As written in agnocastd's config: the pair of topic rules a services rule
  // stands for shows as that services rule.
  for (const WrittenAccessRule& written : written_access_rules(policy->rules)) {
    if (const auto* rule = std::get_if<AccessRule>(&written)) {
      rules.push_back({{"topics", rule->topics},
                       {"publish", principals_json(source, rule->publish)},
                       {"subscribe", principals_json(source, rule->subscribe)}});
    } else {
      const auto& service = std::get<ServiceAccessRule>(written);
      rules.push_back({{"services", service.services},
                       {"serve", principals_json(source, service.serve)},
                       {"call", principals_json(source, service.call)}});
    }
  }
  return {{"policy", {{"default", policy->default_allow ? "allow" : "deny"}, {"rules", rules}}}};
}

std::string policy_show_table(const json& value) {
  const json& policy = value.at("policy");
  if (policy.is_null()) {
    return std::string(no_access_policy_meaning) + "\n";
  }
  std::string text = "default: " + policy.at("default").get<std::string>() +
                     " (what no rule matches, and rights a rule leaves open)\n";
  const json& rules = policy.at("rules");
  if (rules.empty()) return text + "no rules\n";
  // A column per right that some rule has; a rule's other rights stay blank.
  std::vector<std::string> rights;
  for (const char* right : {"publish", "subscribe", "serve", "call"}) {
    if (std::any_of(rules.begin(), rules.end(), [&](const json& r) { return r.contains(right); })) {
      rights.push_back(right);
    }
  }
  std::vector<Table::Column> columns{{"RULE"}};
  for (std::string header : rights) {
    for (char& c : header) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    columns.push_back({header});
  }
  Table table(columns);
  for (const json& rule : rules) {
    const bool topics = rule.contains("topics");
    std::vector<std::string> row{topics ? "topics " + cell(rule.at("topics"))
                                        : "services " + cell(rule.at("services"))};
    for (const std::string& right : rights) {
      row.push_back(rule.contains(right) ? right_cell(rule.at(right)) : "");
    }
    table.add_row(row);
  }
  return text + table.render();
}

void set_policy_command(CLI::App& app, Context& context) {
  CLI::App* policy =
      app.add_subcommand("policy", "The access policy on topics and services (agnocastd's access)");
  policy->require_subcommand(1);
  CLI::App* show = policy->add_subcommand(
      "show",
      "Who may publish and subscribe which topics, serve and call which services; the first "
      "matching rule decides");
  bind_command(*show, context,
               {[&context] { return policy_show_json(context.source); }, policy_show_table});
}

}  // namespace agnocast::cli
