// agnocastd: loads agnocast.ko, then removes what dead agnocast processes
// leave behind until SIGTERM. See SPEC.md §7 and agnocastd/README.md.
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <exception>
#include <functional>
#include <optional>

#include "agnocast/inspect.hpp"
#include "agnocast/supervise.hpp"
#include "agnocastd/status_file.hpp"
#include "config.hpp"
#include "event_loop.hpp"
#include "host.hpp"
#include "instance_lock.hpp"
#include "module_loader.hpp"
#include "mqueue_setup.hpp"
#include "notify.hpp"
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

// Throws CLI::ParseError or agnocastd::ConfigError.
agnocastd::Config read_config(const Options& options, bool config_given) {
  agnocastd::Config config = agnocastd::load_config(options.config_path, !config_given);
  if (options.module_path) config.module_path = options.module_path;
  if (options.no_load) config.load_module = false;
  if (options.log_level) config.log_level = *options.log_level;
  return config;
}

void set_up_logging(const std::string& level) {
  auto logger = spdlog::stderr_logger_st("agnocastd");
  // journald stamps each line itself.
  logger->set_pattern(std::getenv("JOURNAL_STREAM") ? "%^%l%$: %v" : "[%Y-%m-%d %T.%e] [%l] %v");
  logger->set_level(spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::trace);
  spdlog::set_default_logger(logger);
}

// Loads agnocast.ko unless it is there; true when this call loaded it.
bool bring_up_module(const agnocastd::Config& config) {
  if (agnocastd::module_present()) {
    spdlog::info("agnocast.ko is already loaded");
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
  // One daemon at a time, before touching anything.
  agnocastd::InstanceLock lock{std::string(agnocastd::lock_path)};
  // Stop signals queue up from here on; serve() reads them.
  agnocastd::block_daemon_signals();
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
    agnocastd::Supervisor supervisor{config,
                                     std::move(reread_config),
                                     host,
                                     exit_records,
                                     std::string(agnocastd::status_path),
                                     module_version};
    // What died while no daemon ran: first the exits the kernel recorded, then the rest.
    agnocastd::clean_exited_processes(supervisor);
    agnocastd::sweep(host, supervisor.counters);
    agnocastd::write_status(supervisor, /*running=*/true);
    agnocastd::notify("READY=1");
    spdlog::info("agnocastd {} ready", agnocast::library_version_string);
    try {
      agnocastd::serve(supervisor);
    } catch (...) {
      agnocastd::write_status(supervisor, /*running=*/false);
      throw;
    }
    agnocastd::notify("STOPPING=1");
    // Exits that raced the stop signal: nothing is left behind for the next start.
    agnocastd::clean_exited_processes(supervisor);
    agnocastd::write_status(supervisor, /*running=*/false);
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

  const bool config_given = app.count("--config") > 0;
  agnocastd::Config config;
  try {
    config = read_config(options, config_given);
  } catch (const agnocastd::ConfigError& error) {
    fmt::print(stderr, "agnocastd: {}\n", error.what());
    return exit_usage;
  }
  if (options.check_config) {
    fmt::print("agnocastd: configuration {} is valid\n", options.config_path);
    return EXIT_SUCCESS;
  }

  set_up_logging(config.log_level);
  try {
    return run(config, [&options, config_given] { return read_config(options, config_given); });
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
    return exit_failure;
  }
}
