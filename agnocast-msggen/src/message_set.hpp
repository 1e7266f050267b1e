// The messages and services to generate plus every message they refer to,
// checked as a whole: each referenced type exists and no message contains itself.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "message_spec.hpp"

namespace msggen {

class MessageSet {
 public:
  // Where `package`'s .msg files are found (a folder holding Type.msg files).
  void add_package_folder(const std::string& package, const std::filesystem::path& folder);
  // A message (Type.msg) or service (Type.srv) of `package` to generate; its
  // name is the file's stem.
  void add_input(const std::string& package, const std::filesystem::path& file);

  // Parses the inputs and, transitively, what they refer to. Throws InputError.
  void resolve();

  const std::vector<MessageSpec>& inputs() const { return inputs_; }
  const std::vector<ServiceSpec>& services() const { return services_; }

 private:
  const MessageSpec& load(const std::string& package, const std::string& name,
                          const std::string& from_file, int from_line);
  void check_acyclic(const MessageSpec& spec, std::vector<std::string>& path);

  std::map<std::string, std::filesystem::path> folders_;
  std::vector<std::pair<std::string, std::filesystem::path>> input_files_;
  std::vector<std::pair<std::string, std::filesystem::path>> service_files_;
  std::map<std::string, std::filesystem::path> input_by_type_;  // "pkg/Type" -> file
  std::map<std::string, MessageSpec> loaded_;                   // "pkg/Type" -> spec
  std::vector<MessageSpec> inputs_;
  std::vector<ServiceSpec> services_;
};

// Reads and parses one file (name from its stem). Throws InputError.
MessageSpec read_message_file(const std::string& package, const std::filesystem::path& file);
ServiceSpec read_service_file(const std::string& package, const std::filesystem::path& file);

}  // namespace msggen
