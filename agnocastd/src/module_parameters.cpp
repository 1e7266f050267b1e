#include "module_parameters.hpp"

#include <dirent.h>

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <limits>
#include <memory>

#include "agnocast/inspect.hpp"
#include "child_process.hpp"
#include "config.hpp"

namespace agnocastd {
namespace {

constexpr std::string_view array_prefix = "array of ";

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == text.npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

// The kernel parses integers with base 0 (kstrto*): 10, 0x1a, 017.
template <typename Integer>
std::optional<Integer> parsed_integer(std::string_view text) {
  bool negative = false;
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    negative = text[0] == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  } else if (text.size() > 1 && text[0] == '0') {
    base = 8;
    text.remove_prefix(1);
  }
  std::uint64_t magnitude = 0;
  const auto [end, error] =
      std::from_chars(text.data(), text.data() + text.size(), magnitude, base);
  if (text.empty() || error != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  if constexpr (std::numeric_limits<Integer>::is_signed) {
    const auto limit = static_cast<std::uint64_t>(std::numeric_limits<Integer>::max());
    if (magnitude > limit + (negative ? 1 : 0)) return std::nullopt;
    return negative ? static_cast<Integer>(-static_cast<std::int64_t>(magnitude - 1) - 1)
                    : static_cast<Integer>(magnitude);
  } else {
    if (negative || magnitude > std::numeric_limits<Integer>::max()) return std::nullopt;
    return static_cast<Integer>(magnitude);
  }
}

std::optional<bool> parsed_bool(std::string_view text) {
  if (text == "1" || text == "y" || text == "Y" || text == "on") return true;
  if (text == "0" || text == "n" || text == "N" || text == "off") return false;
  return std::nullopt;
}

template <typename Integer>
std::optional<std::string> integer_canonical(std::string_view text) {
  const auto value = parsed_integer<Integer>(text);
  if (!value) return std::nullopt;
  return std::to_string(*value);
}

// The value as /sys/module prints it for this type, or nullopt when the type
// cannot take it. An unknown type takes anything, unchanged.
std::optional<std::string> canonical_scalar(std::string_view type, std::string_view value) {
  if (type == "byte") return integer_canonical<std::uint8_t>(value);
  if (type == "short") return integer_canonical<std::int16_t>(value);
  if (type == "ushort") return integer_canonical<std::uint16_t>(value);
  if (type == "int") return integer_canonical<std::int32_t>(value);
  if (type == "uint" || type == "hexint") return integer_canonical<std::uint32_t>(value);
  if (type == "long" || type == "llong") return integer_canonical<std::int64_t>(value);
  if (type == "ulong" || type == "ullong") return integer_canonical<std::uint64_t>(value);
  if (type == "bool" || type == "invbool") {
    const auto flag = parsed_bool(value);
    if (!flag) return std::nullopt;
    return std::string(*flag ? "Y" : "N");
  }
  return std::string(value);
}

std::optional<std::string> canonical(std::string_view type, std::string_view value) {
  if (!type.starts_with(array_prefix)) return canonical_scalar(type, value);
  const auto element_type = type.substr(array_prefix.size());
  std::string joined;
  std::size_t start = 0;
  for (;;) {
    const auto comma = value.find(',', start);
    const auto element = canonical_scalar(element_type, value.substr(start, comma - start));
    if (!element) return std::nullopt;
    joined += (joined.empty() ? "" : ",") + *element;
    if (comma == value.npos) return joined;
    start = comma + 1;
  }
}

std::string declared_names(const DeclaredParameters& declared) {
  std::string names;
  for (const auto& [name, type] : declared) names += (names.empty() ? "" : ", ") + name;
  return names.empty() ? "none" : names;
}

std::string parameters_directory() {
  return std::string(agnocast::module_sysfs_directory) + "/parameters";
}

std::vector<std::string> parameter_files() {
  std::vector<std::string> names;
  const std::unique_ptr<DIR, int (*)(DIR*)> dir(::opendir(parameters_directory().c_str()),
                                                ::closedir);
  if (!dir) return names;
  while (const dirent* entry = ::readdir(dir.get())) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  return names;
}

}  // namespace

DeclaredParameters parse_parameter_types(std::string_view modinfo_output) {
  DeclaredParameters declared;
  while (!modinfo_output.empty()) {
    const auto end = modinfo_output.find('\n');
    const auto line = trimmed(modinfo_output.substr(0, end));
    modinfo_output.remove_prefix(end == modinfo_output.npos ? modinfo_output.size() : end + 1);
    const auto colon = line.find(':');
    if (colon == line.npos || colon == 0) continue;
    declared[std::string(line.substr(0, colon))] = std::string(trimmed(line.substr(colon + 1)));
  }
  return declared;
}

void check_module_parameters(const ParameterValues& configured,
                             const DeclaredParameters& declared) {
  for (const auto& [name, value] : configured) {
    const auto found = declared.find(name);
    if (found == declared.end()) {
      throw ConfigError("config key 'module_parameters." + name +
                        "': agnocast.ko has no parameter '" + name +
                        "' (it declares: " + declared_names(declared) + ")");
    }
    if (!canonical(found->second, value)) {
      throw ConfigError("config key 'module_parameters." + name + "': '" + value +
                        "' is not a valid " + found->second);
    }
  }
}

std::vector<std::string> loaded_parameter_differences(const ParameterValues& configured,
                                                      const DeclaredParameters& declared,
                                                      const ParameterValues& loaded) {
  std::vector<std::string> lines;
  for (const auto& [name, value] : configured) {
    const auto current = loaded.find(name);
    if (current == loaded.end()) continue;
    const auto type = declared.find(name);
    const std::string wanted =
        canonical(type == declared.end() ? "" : type->second, value).value_or(value);
    if (wanted != current->second) {
      lines.push_back("agnocast.ko is already loaded with " + name + "=" + current->second +
                      ", not module_parameters." + name + "=" + value +
                      ": the configured value applies only after the module is reloaded");
    }
  }
  return lines;
}

std::optional<DeclaredParameters> declared_module_parameters(
    const std::optional<std::string>& module_path) {
  try {
    const auto modinfo = run_child({"modinfo", "-F", "parmtype", module_path.value_or("agnocast")});
    if (modinfo.exited_zero) return parse_parameter_types(modinfo.output);
  } catch (const std::system_error&) {
    // No modinfo: the loaded module may still tell.
  }
  const auto names = parameter_files();
  if (names.empty()) return std::nullopt;
  DeclaredParameters declared;
  for (const auto& name : names) declared[name] = "";
  return declared;
}

ParameterValues loaded_module_parameters() {
  ParameterValues values;
  for (const auto& name : parameter_files()) {
    std::ifstream file(parameters_directory() + "/" + name);
    std::string value;
    if (file && std::getline(file, value)) values[name] = std::string(trimmed(value));
  }
  return values;
}

}  // namespace agnocastd
