// The rules every Kernel follows about wake-ups and held entries, written
// once as a table of scenarios and run against both kernels: natively against
// FakeKernel (kernel_rules_test.cpp) and in the VM against the module through
// Device (tests/kernel_rules_vm_test.cpp), so that the fake the library's
// native tests trust cannot drift from the module.
//
// A scenario's processes act through a World: natively one FakeKernel that
// switches its caller pid, in the VM forked processes that each register and
// run perform() on their own Device, so that a death is a real one.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kernel/kernel.hpp"

namespace agnocast::detail::kernel_rules {

// AGNOCAST_WAKE_WATCHDOG_MS: the VM test checks it against the UAPI header,
// the native one against FakeKernel.
inline constexpr std::chrono::milliseconds watchdog_period{50};
// Bytes of its pool each process offers from pool_base: publishes use
// offsets in it.
inline constexpr std::uint64_t pool_block = 4096;

// One call of one process with every name resolved; plain bytes, so that it
// crosses a pipe.
struct Call {
  enum class Kind : std::uint32_t {
    add_publisher,
    add_subscriber,
    publish,
    notify_failed,
    receive,
    take,
    release,
    reclaim,
    counts,          // the counters of the subscriber subscriber_id
    live_entries,    // the topic's
    wake_signalled,  // reads (drains) the caller's wake_fd()
  };
  static constexpr std::uint32_t ids_max = 4;

  Kind kind = Kind::counts;
  char topic[128] = {};
  std::uint32_t depth = 1;
  bool polling = false;
  bool wake_once = false;
  EndpointId endpoint;
  std::uint32_t subscriber_id = 0;
  std::uint64_t offset = 0;    // publish: where in the caller's pool block
  bool to_one = false;         // publish: to subscriber_id alone
  bool no_drop = false;        // publish: refused rather than dropping or reaching no one
  std::uint32_t id_count = 0;  // release, and receive's release list
  std::uint64_t ids[ids_max] = {};
};

struct Counts {
  std::uint32_t unreceived = 0;
  std::uint32_t held = 0;
  std::uint64_t received = 0;
  std::uint64_t dropped = 0;
  bool operator==(const Counts&) const = default;
};

struct Answer {
  static constexpr std::uint32_t max = 8;

  int error = 0;  // the errno of the DeviceError thrown; 0 when the call succeeded
  EndpointId endpoint;
  std::uint64_t entry_id = 0;
  std::uint32_t wake_count = 0;
  std::uint32_t wake_ids[max] = {};
  std::uint32_t entry_count = 0;  // received or taken
  std::uint64_t entry_ids[max] = {};
  std::uint32_t reclaim_count = 0;
  std::uint64_t reclaimed[max] = {};  // offsets from pool_base
  bool signalled = false;
  Counts counts;
  std::uint32_t live_entries = 0;
};

// Makes the call on kernel as the process whose pool block starts at
// pool_base. Pool grants are closed: no one reads the entries.
Answer perform(Kernel& kernel, std::uint64_t pool_base, const Call& call);

// The kernel as the processes of one scenario see it; a fresh world per run.
class World {
 public:
  virtual ~World() = default;
  virtual Answer perform(int process, const Call& call) = 0;
  // The process dies; returns once the kernel tore it down.
  virtual void kill(int process) = 0;
  // Returns past watchdog_period, the watchdog having acted.
  virtual void pass_watchdog() = 0;
};

// What a subscriber is.
struct Flavor {
  bool polling = false;
  bool wake_once = false;
};
inline constexpr Flavor callback{};
inline constexpr Flavor wake_once{false, true};
inline constexpr Flavor polling{true, false};

// One step of a scenario and what it must give. Endpoints and entries are
// named; a process acts through its own endpoints unless by() says otherwise.
struct Step {
  enum class Kind {
    publisher,
    subscriber,
    publish,
    notify_failed,
    receive,
    take,
    release,
    reclaim,
    counts,
    live_entries,
    signalled,
    kill,
    pass_watchdog,
  };

  Kind kind = Kind::pass_watchdog;
  int process = -1;      // -1: the process of the endpoint named
  std::string endpoint;  // the endpoint made or acted through
  std::string entry;     // publish: the name its entry gets
  std::string subscriber;  // notify_failed; publish: the one it goes to (to())
  bool no_drop = false;    // publish (without_drops())
  std::vector<std::string> ids;  // entries; a name never published stands for an id never issued
  std::uint32_t depth = 1;
  Flavor flavor;

  int error = 0;
  std::optional<std::vector<std::string>> listed;     // publish: the wake ids
  std::optional<std::vector<std::string>> got;        // receive, take: the entries, in order
  std::optional<std::vector<std::string>> reclaimed;  // publish, reclaim: in any order
  std::optional<Counts> counts;
  std::uint32_t live = 0;
  bool signalled = false;

  Step& lists(std::vector<std::string> subscribers);
  Step& gets(std::vector<std::string> entries);
  Step& reclaims(std::vector<std::string> entries);
  Step& releasing(std::vector<std::string> entries);
  Step& fails(int err);
  // publish: to that subscriber alone (a service's response).
  Step& to(std::string subscriber);
  // publish: refused rather than dropping an unreceived entry or reaching no
  // one (a service's request).
  Step& without_drops();
  Step& by(int process);
};

Step publisher(int process, std::string name, std::uint32_t depth = 1, Flavor flavor = {});
Step subscriber(int process, std::string name, Flavor flavor, std::uint32_t depth = 8);
Step publish(std::string publisher, std::string entry);
Step notify_failed(std::string publisher, std::string subscriber);
Step receive(std::string subscriber);
Step take(std::string subscriber);
Step release(std::string subscriber, std::vector<std::string> entries);
Step reclaim(int process);
Step counts(std::string subscriber, Counts expected);
Step live_entries(std::uint32_t expected);
Step signalled(int process);
Step quiet(int process);
Step kill(int process);
Step pass_watchdog();

struct Scenario {
  std::string name;  // an identifier: the test's and the topic's name
  std::string rule;
  int processes = 2;
  std::vector<Step> steps;
};

const std::vector<Scenario>& scenarios();
// The same, as pointers: the parameters of a test over the table.
std::vector<const Scenario*> every_scenario();

using MakeWorld = std::function<std::unique_ptr<World>(int processes)>;

// Runs the scenario in a fresh world; empty when every step gave what it
// must, else the first difference. A run whose steps took long enough for
// the watchdog to act where the scenario does not expect it proves nothing
// and is made again, a few times; runs, when given, is how many were made.
std::string check(const Scenario& scenario, const MakeWorld& make_world, int* runs = nullptr);

}  // namespace agnocast::detail::kernel_rules
