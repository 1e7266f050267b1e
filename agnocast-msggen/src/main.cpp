// agnocast-msggen: ROS 2 .msg and .srv files in, agnocast C++ headers out.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "constant_list_writer.hpp"
#include "header_writer.hpp"
#include "message_set.hpp"

namespace {

// Writes only when the content changed, so that builds depending on it stay up to date.
void write_if_changed(const std::filesystem::path& path, const std::string& content) {
  std::ifstream existing(path);
  if (existing) {
    const std::string old((std::istreambuf_iterator<char>(existing)), {});
    if (old == content) return;
  }
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  out << content;
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Generates agnocast message headers from ROS 2 .msg and .srv files"};
  std::string package;
  std::filesystem::path output;
  std::vector<std::string> includes;
  std::vector<std::filesystem::path> files;
  std::filesystem::path constant_list;
  app.add_option("--package", package, "package of the input messages")->required();
  app.add_option("--output-dir", output, "headers go to DIR/<package>/msg/<name>.hpp (.srv: srv/)")
      ->required();
  app.add_option("--include", includes,
                 "PKG=DIR: where the .msg files of a package the inputs refer to are")
      ->allow_extra_args(false);
  app.add_option(
      "--constant-list", constant_list,
      "also writes FILE: AGNOCAST_CONSTANT(Message, NAME) per constant of the .msg inputs");
  app.add_option("files", files, ".msg and .srv files of the package")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;
  }

  try {
    msggen::MessageSet messages;
    for (const std::string& include : includes) {
      const std::size_t equals = include.find('=');
      if (equals == std::string::npos) {
        std::cerr << "agnocast-msggen: --include wants PKG=DIR, got '" << include << "'\n";
        return 2;
      }
      messages.add_package_folder(include.substr(0, equals), include.substr(equals + 1));
    }
    for (const auto& file : files) messages.add_input(package, file);
    messages.resolve();
    for (const msggen::MessageSpec& spec : messages.inputs()) {
      write_if_changed(output / msggen::header_path(spec.package, spec.name),
                       msggen::write_header(spec));
    }
    for (const msggen::ServiceSpec& spec : messages.services()) {
      write_if_changed(output / msggen::service_header_path(spec.package, spec.name),
                       msggen::write_service_header(spec));
    }
    if (!constant_list.empty()) {
      write_if_changed(constant_list, msggen::write_constant_list(messages.inputs()));
    }
  } catch (const std::exception& error) {
    std::cerr << "agnocast-msggen: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
