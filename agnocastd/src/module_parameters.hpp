// The configured module_parameters checked against what agnocast.ko declares
// (a typo is a configuration error naming it, not a parameter logged as
// applied), and compared with the values of a module already loaded.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace agnocastd {

// Parameter name → its type as the module declares it ("ulong", "uint",
// "bool", "charp", "array of int", ...); empty when only the name is known.
using DeclaredParameters = std::map<std::string, std::string>;
// Parameter name → value, as configured or as /sys/module shows it.
using ParameterValues = std::map<std::string, std::string>;

// Parses `modinfo -F parmtype` output: one "name:type" line per parameter.
DeclaredParameters parse_parameter_types(std::string_view modinfo_output);

// Throws ConfigError naming module_parameters.NAME for a name the module does
// not declare or a value its type cannot take.
void check_module_parameters(const ParameterValues& configured, const DeclaredParameters& declared);

// One line per configured parameter whose loaded value differs, naming both.
std::vector<std::string> loaded_parameter_differences(const ParameterValues& configured,
                                                      const DeclaredParameters& declared,
                                                      const ParameterValues& loaded);

// What agnocast.ko declares: `modinfo -F parmtype` of module_path (or of the
// installed agnocast), else the names a loaded module shows under
// /sys/module/agnocast/parameters; nullopt when neither can tell.
std::optional<DeclaredParameters> declared_module_parameters(
    const std::optional<std::string>& module_path);

// The values of the loaded module's readable parameters (/sys/module).
ParameterValues loaded_module_parameters();

}  // namespace agnocastd
