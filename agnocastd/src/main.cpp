// agnocastd: loads agnocast.ko, then removes what dead agnocast processes
// leave behind until SIGTERM. See agnocastd/README.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <exception>
#include <functional>
#include <optional>

#include "agnocast/inspect.hpp"
#include "agnocast/status.hpp"
#include "agnocast/supervise.hpp"
#include "agnocast_service/journal_log.hpp"
#include "agnocast_service/service_loop.hpp"
#include "config.hpp"
#include "daemon_signals.hpp"
#include "event_loop.hpp"
#include "host.hpp"
#include "module_loader.hpp"
#include "module_parameters.hpp"
#include "mqueue_setup.hpp"
#include "reload.hpp"
#include "sweeper.hpp"

namespace {

constexpr int exit_failure = 1;
constexpr int exit_usage = 2;

struct Options {
  std::string config_path{agnocastd::default_config_path};
  std::optional<std::string> module_path;
  bool no_load = false;
  std::optional<std::string> log_level;
  bool check_config = false;
};

// A parameter agnocast.ko does not declare, or a value its type cannot take,
// is a configuration error: it would otherwise fail the load, or be ignored.
void check_module_parameters(const agnocastd::Config& config) {
  if (config.module_parameters.empty()) return;
  const auto declared = agnocastd::declared_module_parameters(config.module_path);
  if (!declared) {
    spdlog::warn(
        "module_parameters not checked: modinfo cannot read {} and agnocast.ko is not loaded",
        config.module_path.value_or("the installed agnocast module"));
    return;
  }
  agnocastd::check_module_parameters(config.module_parameters, *declared);
}

// Throws CLI::ParseError or agnocastd::ConfigError.
agnocastd::Config read_config(const Options& options, bool config_given) {
  agnocastd::Config config = agnocastd::load_config(options.config_path, !config_given);
  if (options.module_path) config.module_path = options.module_path;
  if (options.no_load) config.load_module = false;
  if (options.log_level) config.log_level = *options.log_level;
  check_module_parameters(config);
  return config;
}

// A module someone else loaded keeps its parameters: say where they differ.
void log_loaded_parameter_differences(const agnocastd::Config& config) {
  if (config.module_parameters.empty()) return;
  const auto declared = agnocastd::declared_module_parameters(config.module_path);
  for (const auto& difference : agnocastd::loaded_parameter_differences(
           config.module_parameters, declared.value_or(agnocastd::DeclaredParameters{}),
           agnocastd::loaded_module_parameters())) {
    spdlog::warn("{}", difference);
  }
}

// Loads agnocast.ko unless it is there; true when this call loaded it.
bool bring_up_module(const agnocastd::Config& config) {
  if (agnocastd::module_present()) {
    spdlog::info("agnocast.ko is already loaded");
    log_loaded_parameter_differences(config);
    return false;
  }
  if (!config.load_module) {
    throw agnocastd::ModuleError(
        "agnocast.ko is not loaded and --no-load forbids loading it: load it (modprobe agnocast) "
        "or start agnocastd without --no-load");
  }
  agnocastd::load_module(config.module_path, config.module_parameters);
  spdlog::info("loaded agnocast.ko ({}) {}", config.module_path.value_or("modprobe"),
               agnocastd::module_parameter_string(config.module_parameters));
  return true;
}

std::string checked_module_version(const agnocastd::Config& config) {
  if (!agnocastd::wait_for_device(config.device_timeout)) {
    throw agnocastd::ModuleError("/dev/agnocast did not appear within " +
                                 std::to_string(config.device_timeout.count()) + " ms");
  }
  const auto version = agnocast::module_version();
  if (!version) throw agnocastd::ModuleError("/dev/agnocast vanished");
  if (const auto problem = agnocastd::version_problem(*version); !problem.empty()) {
    throw agnocastd::ModuleError(problem);
  }
  return version->to_string();
}

void stop_module(bool loaded_here, bool unload_on_exit) {
  if (!loaded_here || !unload_on_exit) return;
  switch (agnocastd::unload_module()) {
    case agnocastd::UnloadResult::unloaded:
      spdlog::info("unloaded agnocast.ko");
      break;
    case agnocastd::UnloadResult::busy:
      spdlog::warn("agnocast.ko is still in use: left loaded");
      break;
    case agnocastd::UnloadResult::failed:
      spdlog::warn("could not unload agnocast.ko");
      break;
  }
}

int run(const agnocastd::Config& config, std::function<agnocastd::Config()> reread_config) {
  // One daemon at a time, before touching anything; the stop and reload
  // signals queue from here on (stop_requested() and the serve loop read them).
  agnocast_service::ServiceLoop service(
      {.program = "agnocastd", .status_path = std::string(agnocast::daemon_status_path)});
  // The module, its version and the device permissions: clients need all three.
  const bool loaded_here = bring_up_module(config);
  const std::string module_version = checked_module_version(config);
  spdlog::info("agnocast.ko {} is compatible with agnocastd {}", module_version,
               agnocast::library_version_string);
  agnocastd::apply_device_permissions(config.device);
  // Queues are listed and limited through the mqueue filesystem and sysctls.
  agnocastd::ensure_mqueue_mounted();
  agnocastd::apply_mqueue_limits(config.mqueue);
  // unload_on_exit as the configuration in force at stop says.
  bool unload_on_exit = config.unload_on_exit;
  {
    agnocast::ExitRecordReader exit_records;
    // Before READY=1: no client may create an endpoint the policy would
    // refuse. Set while exit_records is open, whose descriptor keeps the
    // namespace's kernel state (and so the policy) alive.
    agnocastd::apply_access_policy(config.access);
    agnocastd::SystemHost host;
    agnocastd::Supervisor supervisor{
        config, std::move(reread_config), host, exit_records, service, module_version};
    // What died while no daemon ran: first the exits the kernel recorded, then the rest.
    agnocastd::clean_exited_processes(supervisor);
    agnocastd::sweep(host, supervisor.counters);
    // READY=1, then serve until a stop signal (a failure's last status is the service's).
    agnocastd::serve(supervisor);
    // Exits that raced the stop signal: nothing is left behind for the next start.
    agnocastd::clean_exited_processes(supervisor);
    service.stopped();
    unload_on_exit = supervisor.config.unload_on_exit;
  }
  // The exit-record descriptor is closed now; it would keep the module busy.
  stop_module(loaded_here, unload_on_exit);
  spdlog::info("agnocastd stopped");
  return EXIT_SUCCESS;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"agnocastd: loads agnocast.ko and cleans up after dead agnocast processes"};
  Options options;
  app.add_option("--config", options.config_path, "JSON configuration file")->capture_default_str();
  auto* module = app.add_option("--module", options.module_path, "agnocast.ko to insmod");
  app.add_flag("--no-load", options.no_load, "Never load the module; fail if it is not loaded")
      ->excludes(module);
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error, critical, off")
      ->check([](const std::string& level) {
        return agnocastd::is_log_level(level) ? "" : "unknown log level '" + level + "'";
      });
  app.add_flag("--check-config", options.check_config, "Validate the configuration and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == EXIT_SUCCESS ? EXIT_SUCCESS : exit_usage;  // --help is no error
  }

  // Before the configuration: reading it may log.
  agnocast_service::set_up_logging("agnocastd", options.log_level.value_or("info"),
                                   agnocast_service::stderr_is_journal());
  const bool config_given = app.count("--config") > 0;
  agnocastd::Config config;
  try {
    config = read_config(options, config_given);
  } catch (const agnocastd::ConfigError& error) {
    spdlog::error("{}", error.what());
    return exit_usage;
  }
  if (options.check_config) {
    fmt::print("agnocastd: configuration {} is valid\n", options.config_path);
    return EXIT_SUCCESS;
  }

  spdlog::set_level(spdlog::level::from_str(config.log_level));
  try {
    return run(config, [&options, config_given] { return read_config(options, config_given); });
  } catch (const agnocastd::StopRequested& stop) {
    spdlog::info("agnocastd stopped while starting ({})", stop.what());
    return EXIT_SUCCESS;
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
    return exit_failure;
  }
}
