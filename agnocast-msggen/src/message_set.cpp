#include "message_set.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "msg_parser.hpp"

namespace msggen {
namespace {

std::string key(const std::string& package, const std::string& name) {
  return package + "/" + name;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) throw InputError(file.string(), 0, "cannot read the file");
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

}  // namespace

MessageSpec read_message_file(const std::string& package, const std::filesystem::path& file) {
  return parse_message(read_text(file), file.string(), package, file.stem().string());
}

ServiceSpec read_service_file(const std::string& package, const std::filesystem::path& file) {
  return parse_service(read_text(file), file.string(), package, file.stem().string());
}

void MessageSet::add_package_folder(const std::string& package,
                                    const std::filesystem::path& folder) {
  folders_[package] = folder;
}

void MessageSet::add_input(const std::string& package, const std::filesystem::path& file) {
  if (file.extension() == ".srv") {
    service_files_.emplace_back(package, file);
    return;
  }
  input_files_.emplace_back(package, file);
  input_by_type_[key(package, file.stem().string())] = file;
}

const MessageSpec& MessageSet::load(const std::string& package, const std::string& name,
                                    const std::string& from_file, int from_line) {
  const std::string type = key(package, name);
  if (const auto found = loaded_.find(type); found != loaded_.end()) return found->second;
  std::filesystem::path file;
  if (const auto input = input_by_type_.find(type); input != input_by_type_.end()) {
    file = input->second;
  } else if (const auto folder = folders_.find(package); folder != folders_.end()) {
    file = folder->second / (name + ".msg");
  }
  if (file.empty() || !std::filesystem::exists(file)) {
    throw InputError(from_file, from_line,
                     fmt::format("unknown type '{}': no {}.msg among the inputs or in the "
                                 "folders given for package '{}' (DEPENDENCIES / --include)",
                                 type, name, package));
  }
  return loaded_.emplace(type, read_message_file(package, file)).first->second;
}

void MessageSet::check_acyclic(const MessageSpec& spec, std::vector<std::string>& path) {
  path.push_back(key(spec.package, spec.name));
  for (const Field& field : spec.fields) {
    if (field.type.base != BaseType::Message) continue;
    const std::string type = key(field.type.package, field.type.name);
    if (std::find(path.begin(), path.end(), type) != path.end()) {
      std::string chain;
      for (const std::string& step : path) chain += step + " -> ";
      throw InputError(spec.file, field.line, fmt::format("cyclic include: {}{}", chain, type));
    }
    check_acyclic(load(field.type.package, field.type.name, spec.file, field.line), path);
  }
  path.pop_back();
}

void MessageSet::resolve() {
  inputs_.clear();
  for (const auto& [package, file] : input_files_) {
    const MessageSpec& spec = load(package, file.stem().string(), file.string(), 0);
    std::vector<std::string> path;
    check_acyclic(spec, path);
    inputs_.push_back(spec);
  }
  services_.clear();
  for (const auto& [package, file] : service_files_) {
    ServiceSpec spec = read_service_file(package, file);
    for (const MessageSpec* part : {&spec.request, &spec.response}) {
      std::vector<std::string> path;
      check_acyclic(*part, path);
    }
    services_.push_back(std::move(spec));
  }
}

}  // namespace msggen
