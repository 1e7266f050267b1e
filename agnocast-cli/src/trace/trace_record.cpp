#include "trace/trace_record.hpp"

#include <fcntl.h>
#include <grp.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <vector>

#include "agnocast/signals.hpp"
#include "cli.hpp"
#include "trace/chrome_trace.hpp"

extern char** environ;

namespace agnocast::cli {
namespace {

namespace fs = std::filesystem;

constexpr double sample_interval_s = 0.1;

std::int64_t monotonic_ns() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "/usr/bin:/bin");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (!folder.empty() && ::access((folder + "/" + program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// Runs `argv` with stdin from /dev/null; its stdout and stderr go to
// `output` (when given) or to /dev/null. Returns its exit status (-1: it
// could not start or was killed).
int run(const std::vector<std::string>& argv, std::string* output = nullptr) {
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  int pipe_fds[2] = {-1, -1};
  if (output && ::pipe2(pipe_fds, O_CLOEXEC) != 0) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  if (output) {
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  } else {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  }
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (output) {
    ::close(pipe_fds[1]);
    if (spawned == 0) {
      std::array<char, 65536> buffer;
      for (;;) {
        const ssize_t got = ::read(pipe_fds[0], buffer.data(), buffer.size());
        if (got > 0) {
          output->append(buffer.data(), static_cast<std::size_t>(got));
        } else if (got == 0 || errno != EINTR) {
          break;
        }
      }
    }
    ::close(pipe_fds[0]);
  }
  if (spawned != 0) return -1;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void require_permission() {
  if (::geteuid() == 0) return;
  if (const group* tracing = ::getgrnam("tracing")) {
    std::vector<gid_t> groups(static_cast<std::size_t>(std::max(::getgroups(0, nullptr), 0)));
    const int count = ::getgroups(static_cast<int>(groups.size()), groups.data());
    for (int i = 0; i < count; ++i) {
      if (groups[static_cast<std::size_t>(i)] == tracing->gr_gid) return;
    }
  }
  throw CliError(
      "trace record needs root, or membership of the tracing group and the system's LTTng "
      "session daemon (sudo usermod -aG tracing $USER, log in again, and sudo systemctl start "
      "lttng-sessiond)");
}

// The LTTng session of this recording, with a session daemon of its own when
// none ran; everything it made goes when it goes.
class LttngSession {
 public:
  explicit LttngSession(const fs::path& folder)
      : name_("agnocast-cli-" + std::to_string(::getpid())), folder_(folder) {
    if (run({"lttng", "--no-sessiond", "list"}) != 0) start_daemon();
    lttng({"create", name_, "--output=" + folder_.string()});
    created_ = true;
    lttng({"enable-event", "--userspace", "agnocast:*", "--session=" + name_});
    lttng({"add-context", "--userspace", "--type=vpid", "--type=vtid", "--type=procname",
           "--session=" + name_});
    lttng({"start", name_});
  }
  ~LttngSession() {
    if (created_) run({"lttng", "destroy", name_});
    if (daemon_ > 0) {
      ::kill(daemon_, SIGTERM);
      int status = 0;
      while (::waitpid(daemon_, &status, 0) < 0 && errno == EINTR) {
      }
    }
  }
  LttngSession(const LttngSession&) = delete;
  LttngSession& operator=(const LttngSession&) = delete;

  // Stops the session; its trace is then whole in the folder.
  void stop() { lttng({"stop", name_}); }
  bool started_daemon() const { return daemon_ > 0; }

 private:
  // Never lets lttng start a daemon itself: this session manages its own.
  void lttng(std::vector<std::string> args) {
    args.insert(args.begin(), {"lttng", "--no-sessiond"});
    std::string output;
    if (run(args, &output) != 0) {
      throw CliError("lttng " + args[2] + " failed: " + output);
    }
  }

  // A session daemon as this process's child; processes already running
  // register with it once it is up (LTTng-UST waits for one).
  void start_daemon() {
    const char* argv[] = {"lttng-sessiond", "--no-kernel", nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    // A group of its own: the terminal's Ctrl-C, which ends the recording,
    // must not end the daemon before the recording is stopped and read.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);
    const int spawned = ::posix_spawnp(&daemon_, argv[0], &actions, &attributes,
                                       const_cast<char* const*>(argv), environ);
    posix_spawnattr_destroy(&attributes);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) {
      daemon_ = 0;
      throw CliError(std::string("cannot start lttng-sessiond: ") + std::strerror(spawned));
    }
    for (int attempt = 0; attempt < 600; ++attempt) {
      int status = 0;
      if (::waitpid(daemon_, &status, WNOHANG) == daemon_) {
        daemon_ = 0;
        throw CliError("lttng-sessiond exited at once (status " + std::to_string(status) +
                       "): run lttng-sessiond -vv to see why");
      }
      if (run({"lttng", "--no-sessiond", "list"}) == 0) {
        // Let the processes that start now register before the session starts.
        ::usleep(500'000);
        return;
      }
      ::usleep(50'000);
    }
    throw CliError("lttng-sessiond did not answer within 30 s");
  }

  const std::string name_;
  const fs::path folder_;
  pid_t daemon_ = 0;
  bool created_ = false;
};

// The module's events in a tracefs instance of this recording's own, on the
// monotonic clock LTTng uses; nullopt reason when it could not be made.
class KernelEvents {
 public:
  KernelEvents() {
    for (const char* root : {"/sys/kernel/tracing", "/sys/kernel/debug/tracing"}) {
      if (fs::exists(fs::path(root) / "events" / "agnocast")) {
        instance_ = fs::path(root) / "instances" / ("agnocast-cli-" + std::to_string(::getpid()));
        break;
      }
    }
    if (instance_.empty()) {
      problem_ = "no agnocast events in tracefs (module not loaded, or tracefs not mounted)";
      return;
    }
    std::error_code error;
    if (!fs::create_directory(instance_, error)) {
      problem_ = "cannot make " + instance_.string() + ": " + error.message();
      instance_.clear();
      return;
    }
    if (!write("trace_clock", "mono") || !write("buffer_size_kb", "8192") ||
        !write("events/agnocast/enable", "1")) {
      problem_ = "cannot set up " + instance_.string();
    }
  }
  ~KernelEvents() {
    if (instance_.empty()) return;
    write("events/agnocast/enable", "0");
    ::rmdir(instance_.c_str());
  }
  KernelEvents(const KernelEvents&) = delete;
  KernelEvents& operator=(const KernelEvents&) = delete;

  const std::string& problem() const { return problem_; }

  std::vector<TraceEvent> take() {
    if (instance_.empty() || !problem_.empty()) return {};
    write("tracing_on", "0");
    std::ifstream in(instance_ / "trace");
    std::stringstream text;
    text << in.rdbuf();
    return parse_tracefs_text(text.str());
  }

 private:
  bool write(const char* file, const char* value) {
    std::ofstream out(instance_ / file);
    out << value;
    out.flush();
    return static_cast<bool>(out);
  }

  fs::path instance_;
  std::string problem_;
};

struct TempFolder {
  fs::path path;
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "agnocast-trace-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) {
      throw CliError(std::string("cannot make a temporary folder: ") + std::strerror(errno));
    }
    path = pattern;
  }
  ~TempFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

// The agnocast processes alive now, when the module can be asked.
std::set<int> agnocast_pids(InspectionSource& source) {
  std::set<int> pids;
  try {
    for (const ProcessInfo& process : source.list_processes()) pids.insert(process.pid);
  } catch (const std::exception&) {
  }
  return pids;
}

std::string default_output() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  ::localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof name, "agnocast-trace-%Y-%m-%d_%H-%M-%S.json", &local);
  return name;
}

// One sample of every topic's counts; what went wrong, when the module
// cannot be asked (the recording goes on without counts).
std::string sample_counts(InspectionSource& source, const std::optional<std::regex>& topics,
                          RecordedTrace& trace) try {
  const std::int64_t now = monotonic_ns();
  for (const TopicSummary& summary : source.list_topics()) {
    if (topics && !std::regex_search(summary.name, *topics)) continue;
    const std::optional<TopicInfo> info = source.topic_info(summary.name);
    if (!info) continue;
    EntryCounts sample{now, summary.name, 0, 0};
    for (const SubscriberInfo& subscriber : info->subscribers) {
      sample.held += subscriber.held;
      sample.unreceived += subscriber.unreceived;
      trace.subscriber_nodes[{summary.name, subscriber.id}] = subscriber.node;
    }
    for (const PublisherInfo& publisher : info->publishers) {
      trace.publisher_nodes[{summary.name, publisher.id}] = publisher.node;
    }
    trace.counts.push_back(sample);
  }
  return {};
} catch (const std::exception& error) {
  return error.what();
}

}  // namespace

int trace_record(InspectionSource& source, const TraceRecordOptions& options, std::ostream& out) {
  RecordedTrace trace;
  if (options.topics) {
    try {
      trace.topics.emplace(*options.topics, std::regex::ECMAScript | std::regex::optimize);
    } catch (const std::regex_error& error) {
      throw InputError("--topics '" + *options.topics +
                       "' is not a regular expression: " + error.what());
    }
    bool any = false;
    for (const TopicSummary& summary : source.list_topics()) {
      any = any || std::regex_search(summary.name, *trace.topics);
    }
    if (!any) {
      throw InputError("no topic matches --topics '" + *options.topics +
                       "' (agnocast-cli topic list shows them)");
    }
  }
  for (const char* tool : {"lttng", "lttng-sessiond", "babeltrace2"}) {
    if (!on_path(tool)) {
      throw CliError(std::string("trace record needs ") + tool +
                     ": sudo apt-get install lttng-tools babeltrace2");
    }
  }
  require_permission();
  const std::string output = options.output.empty() ? default_output() : options.output;
  // Fail before recording when the file cannot be written.
  const fs::path parent = fs::path(output).has_parent_path() ? fs::path(output).parent_path() : ".";
  if (fs::is_directory(output) || ::access(parent.c_str(), W_OK) != 0) {
    throw CliError("cannot write " + output + ": give -o a file in a folder you can write");
  }

  install_signal_handlers();  // SIGINT/SIGTERM end the recording, which is then written
  const std::set<int> running = agnocast_pids(source);
  TempFolder folder;
  // LTTng's tools keep their settings in a home folder; a service has none.
  if (!std::getenv("HOME") && !std::getenv("LTTNG_HOME")) {
    ::setenv("LTTNG_HOME", folder.path.c_str(), 1);
  }
  KernelEvents kernel;
  std::string kernel_problem = kernel.problem();
  std::string counts_problem;
  {
    LttngSession session(folder.path / "lttng");
    const double start = source.now_seconds();
    while (!source.stop_requested() &&
           (!options.duration_s || source.now_seconds() - start < *options.duration_s)) {
      if (std::string problem = sample_counts(source, trace.topics, trace);
          !problem.empty() && counts_problem.empty()) {
        counts_problem = std::move(problem);
      }
      double wait = sample_interval_s;
      if (options.duration_s) {
        wait = std::min(wait, std::max(0.0, *options.duration_s - (source.now_seconds() - start)));
      }
      source.sleep_seconds(wait);
    }
    sample_counts(source, trace.topics, trace);
    session.stop();
    trace.kernel = kernel.take();
  }
  if (fs::exists(folder.path / "lttng")) {
    std::string text;
    if (run({"babeltrace2", "--clock-cycles", "--no-delta", (folder.path / "lttng").string()},
            &text) != 0) {
      throw CliError("babeltrace2 could not read the recorded trace: " + text.substr(0, 2000));
    }
    trace.library = parse_lttng_text(text);
  }
  // Processes that lived throughout and sent nothing were idle, or carry no
  // probes: they started while no session daemon listened
  // (libagnocast/README.md, "Tracing").
  std::set<int> silent = running;
  for (const TraceEvent& event : trace.library) silent.erase(event.pid);
  const std::set<int> alive = agnocast_pids(source);
  std::erase_if(silent, [&](int pid) { return !alive.contains(pid); });
  const nlohmann::json chrome = chrome_trace(trace);
  {
    std::ofstream file(output, std::ios::trunc);
    file << chrome.dump() << '\n';
    if (!file.flush()) {
      const std::string why = std::strerror(errno);
      std::remove(output.c_str());  // no half a trace left behind
      throw CliError("cannot write " + output + ": " + why);
    }
  }
  const nlohmann::json& other = chrome["otherData"];
  nlohmann::json summary = {
      {"file", output},
      {"library_events", other["library_events"]},
      {"kernel_events", other["kernel_events"]},
      {"callbacks", other["callbacks"]},
      {"flows", other["flows"]},
      {"kernel", kernel_problem.empty() ? nlohmann::json(true) : nlohmann::json(kernel_problem)},
      {"counts", counts_problem.empty() ? nlohmann::json(true) : nlohmann::json(counts_problem)},
      {"silent_pids", silent}};
  if (options.json) {
    out << summary.dump() << '\n';
  } else {
    out << "wrote " << output << ": " << other["library_events"] << " library events, "
        << other["kernel_events"] << " kernel events, " << other["callbacks"] << " callbacks, "
        << other["flows"] << " flows from publish to callback\n";
    if (!kernel_problem.empty()) out << "kernel events left out: " << kernel_problem << '\n';
    if (!counts_problem.empty()) out << "entry counts left out: " << counts_problem << '\n';
    if (!silent.empty()) {
      out << silent.size() << " agnocast processes sent no events (pids";
      for (const int pid : silent) out << ' ' << pid;
      out << "): idle, or started while no LTTng session daemon ran; for those, start "
             "lttng-sessiond before them (systemctl start lttng-sessiond), or start them with "
             "AGNOCAST_LTTNG=1\n";
    }
    if (trace.library.empty()) {
      out << "no library events: no agnocast process ran, or libagnocast was built with "
             "AGNOCAST_TRACING=OFF\n";
    }
  }
  return exit_success;
}

}  // namespace agnocast::cli
