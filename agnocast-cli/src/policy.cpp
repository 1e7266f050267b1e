// agnocast-cli policy show: the topic access policy the kernel enforces in
// this IPC namespace (agnocastd/README.md, "access"), with user and group ids shown by name.
#include <string>

#include "agnocast/access_policy.hpp"
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

// A direction's cell: who is listed, "(nobody)" for an empty list, or
// "(default)" when the rule leaves it to the default.
std::string direction_cell(const json& principals) {
  if (principals.is_null()) return "(default)";
  if (principals.empty()) return "(nobody)";
  return cell(principals);
}

}  // namespace

json policy_show_json(InspectionSource& source) {
  const std::optional<AccessPolicy> policy = source.access_policy();
  if (!policy) return {{"policy", nullptr}};
  json rules = json::array();
  for (const AccessRule& rule : policy->rules) {
    rules.push_back({{"topics", rule.topics},
                     {"publish", principals_json(source, rule.publish)},
                     {"subscribe", principals_json(source, rule.subscribe)}});
  }
  return {{"policy", {{"default", policy->default_allow ? "allow" : "deny"}, {"rules", rules}}}};
}

std::string policy_show_table(const json& value) {
  const json& policy = value.at("policy");
  if (policy.is_null()) {
    return std::string(no_access_policy_meaning) + "\n";
  }
  std::string text = "default: " + policy.at("default").get<std::string>() +
                     " (topics no rule matches, and directions a rule leaves open)\n";
  if (policy.at("rules").empty()) return text + "no rules\n";
  Table table({{"TOPICS"}, {"PUBLISH"}, {"SUBSCRIBE"}});
  for (const json& rule : policy.at("rules")) {
    table.add_row({cell(rule.at("topics")), direction_cell(rule.at("publish")),
                   direction_cell(rule.at("subscribe"))});
  }
  return text + table.render();
}

void set_policy_command(CLI::App& app, Context& context) {
  CLI::App* policy = app.add_subcommand("policy", "The topic access policy (agnocastd's access)");
  policy->require_subcommand(1);
  CLI::App* show = policy->add_subcommand(
      "show", "Who may publish and subscribe which topics; the first matching rule decides");
  bind_command(*show, context,
               {[&context] { return policy_show_json(context.source); }, policy_show_table});
}

}  // namespace agnocast::cli
