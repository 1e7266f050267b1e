#include "kernel/kernel_rules.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <map>
#include <span>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "agnocast/errors.hpp"

namespace agnocast::detail::kernel_rules {

Answer perform(Kernel& kernel, std::uint64_t pool_base, const Call& call) {
  Answer answer;
  const auto offsets = [&](std::span<const std::uint64_t> addresses) {
    answer.reclaim_count = static_cast<std::uint32_t>(addresses.size());
    for (std::size_t i = 0; i < addresses.size(); ++i)
      answer.reclaimed[i] = addresses[i] - pool_base;
  };
  try {
    switch (call.kind) {
      case Call::Kind::add_publisher:
      case Call::Kind::add_subscriber: {
        EndpointRequest request;
        request.topic = call.topic;
        request.node = "kernel_rules";
        request.depth = call.depth;
        request.polling = call.polling;
        request.wake_once = call.wake_once;
        request.type_name = "kernel_rules/Entry";
        request.type_hash = 1;
        answer.endpoint = call.kind == Call::Kind::add_publisher ? kernel.add_publisher(request)
                                                                 : kernel.add_subscriber(request);
        break;
      }
      case Call::Kind::publish: {
        std::array<std::uint32_t, Answer::max> wake{};
        std::array<std::uint64_t, Answer::max> reclaim{};
        ServiceRoute route;
        if (call.to_one) route.to_subscriber = call.subscriber_id;
        route.no_drop = call.no_drop;
        const PublishResult result =
            kernel.publish(call.endpoint, pool_base + call.offset, 8, wake, reclaim, route);
        answer.entry_id = result.entry_id;
        answer.wake_count = result.wake_count;
        std::copy_n(wake.begin(), result.wake_count, answer.wake_ids);
        offsets(std::span(reclaim).first(result.reclaim_count));
        break;
      }
      case Call::Kind::notify_failed:
        kernel.notify_failed(call.endpoint, call.subscriber_id);
        break;
      case Call::Kind::receive: {
        std::array<ReceivedEntry, Answer::max> entries{};
        std::array<PoolGrant, Kernel::receive_pools_max> pools{};
        const ReceiveResult result =
            kernel.receive(call.endpoint, entries, pools, std::span(call.ids, call.id_count));
        for (std::uint32_t i = 0; i < result.pool_count; ++i) ::close(pools[i].fd);
        answer.entry_count = result.entry_count;
        for (std::uint32_t i = 0; i < result.entry_count; ++i) {
          answer.entry_ids[i] = entries[i].entry_id;
        }
        break;
      }
      case Call::Kind::take: {
        const TakeResult result = kernel.take(call.endpoint);
        if (result.has_pool) ::close(result.pool.fd);
        if (result.has_entry) answer.entry_ids[answer.entry_count++] = result.entry.entry_id;
        break;
      }
      case Call::Kind::release:
        kernel.release(call.endpoint, std::span(call.ids, call.id_count));
        break;
      case Call::Kind::reclaim: {
        std::array<std::uint64_t, Answer::max> reclaim{};
        offsets(std::span(reclaim).first(kernel.reclaim(reclaim).reclaim_count));
        break;
      }
      case Call::Kind::counts:
      case Call::Kind::live_entries: {
        TopicInfo info;
        if (!kernel.topic_info(call.topic, info)) throw DeviceError(ENOENT, "no such topic");
        answer.live_entries = info.entries;
        if (call.kind == Call::Kind::live_entries) break;
        const auto found = std::find_if(
            info.subscribers.begin(), info.subscribers.end(),
            [&](const SubscriberInfo& subscriber) { return subscriber.id == call.subscriber_id; });
        if (found == info.subscribers.end()) throw DeviceError(ENOENT, "no such subscriber");
        answer.counts = Counts{found->unreceived, found->held, found->received, found->dropped};
        break;
      }
      case Call::Kind::wake_signalled: {
        std::uint64_t count = 0;
        const int fd = kernel.wake_fd();
        answer.signalled = fd >= 0 && ::read(fd, &count, sizeof count) == sizeof count;
        break;
      }
    }
  } catch (const DeviceError& error) {
    answer.error = error.code();
  }
  return answer;
}

namespace {

Step step_of(Step::Kind kind) {
  Step step;
  step.kind = kind;
  return step;
}

}  // namespace

Step& Step::lists(std::vector<std::string> subscribers) {
  listed = std::move(subscribers);
  return *this;
}

Step& Step::gets(std::vector<std::string> entries) {
  got = std::move(entries);
  return *this;
}

Step& Step::reclaims(std::vector<std::string> entries) {
  reclaimed = std::move(entries);
  return *this;
}

Step& Step::releasing(std::vector<std::string> entries) {
  ids = std::move(entries);
  return *this;
}

Step& Step::fails(int err) {
  error = err;
  return *this;
}

Step& Step::to(std::string one) {
  subscriber = std::move(one);
  return *this;
}

Step& Step::without_drops() {
  no_drop = true;
  return *this;
}

Step& Step::by(int acting) {
  process = acting;
  return *this;
}

Step publisher(int process, std::string name, std::uint32_t depth, Flavor flavor) {
  Step step = step_of(Step::Kind::publisher);
  step.process = process;
  step.endpoint = std::move(name);
  step.depth = depth;
  step.flavor = flavor;
  return step;
}

Step subscriber(int process, std::string name, Flavor flavor, std::uint32_t depth) {
  Step step = publisher(process, std::move(name), depth, flavor);
  step.kind = Step::Kind::subscriber;
  return step;
}

Step publish(std::string publisher, std::string entry) {
  Step step = step_of(Step::Kind::publish);
  step.endpoint = std::move(publisher);
  step.entry = std::move(entry);
  return step;
}

Step notify_failed(std::string publisher, std::string subscriber) {
  Step step = step_of(Step::Kind::notify_failed);
  step.endpoint = std::move(publisher);
  step.subscriber = std::move(subscriber);
  return step;
}

Step receive(std::string subscriber) {
  Step step = step_of(Step::Kind::receive);
  step.endpoint = std::move(subscriber);
  return step;
}

Step take(std::string subscriber) {
  Step step = step_of(Step::Kind::take);
  step.endpoint = std::move(subscriber);
  return step;
}

Step release(std::string subscriber, std::vector<std::string> entries) {
  Step step = step_of(Step::Kind::release);
  step.endpoint = std::move(subscriber);
  step.ids = std::move(entries);
  return step;
}

Step reclaim(int process) {
  Step step = step_of(Step::Kind::reclaim);
  step.process = process;
  return step;
}

Step counts(std::string subscriber, Counts expected) {
  Step step = step_of(Step::Kind::counts);
  step.endpoint = std::move(subscriber);
  step.counts = expected;
  return step;
}

Step live_entries(std::uint32_t expected) {
  Step step = step_of(Step::Kind::live_entries);
  step.live = expected;
  return step;
}

Step signalled(int process) {
  Step step = step_of(Step::Kind::signalled);
  step.process = process;
  step.signalled = true;
  return step;
}

Step quiet(int process) {
  Step step = signalled(process);
  step.signalled = false;
  return step;
}

Step kill(int process) {
  Step step = step_of(Step::Kind::kill);
  step.process = process;
  return step;
}

Step pass_watchdog() { return step_of(Step::Kind::pass_watchdog); }

// Processes: 0 publishes, 1 subscribes, 2 publishes too (or subscribes).
std::vector<const Scenario*> every_scenario() {
  std::vector<const Scenario*> all;
  for (const Scenario& scenario : scenarios()) all.push_back(&scenario);
  return all;
}

const std::vector<Scenario>& scenarios() {
  static const std::vector<Scenario> table = {
      // Wake-ups.
      {"WakeOnceIsListedOnceUntilItLooks",
       "a wake-once subscriber is listed by one PUBLISH until it RECEIVEs",
       2,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publish("p", "e1").lists({"w"}),
        publish("p", "e2").lists({}), receive("w").gets({"e1", "e2"}),
        publish("p", "e3").lists({"w"})}},
      {"CallbackIsListedByEveryPublishPollingByNone",
       "a plain callback subscriber is listed by every PUBLISH, a polling one by none",
       2,
       {subscriber(1, "c", callback), subscriber(1, "q", polling), publisher(0, "p"),
        publish("p", "e1").lists({"c"}), publish("p", "e2").lists({"c"}),
        counts("q", {.unreceived = 2})}},
      {"FailedReceiveStillLooks",
       "a RECEIVE that fails (its release list names an entry not held) counts as looking",
       2,
       {subscriber(1, "w", wake_once), publisher(0, "p", 4), publish("p", "e1").lists({"w"}),
        receive("w").releasing({"never"}).fails(ENOENT), counts("w", {.unreceived = 1}),
        publish("p", "e2").lists({"w"})}},
      {"NotifyFailedBeforeItLookedListsAgainAndSignals",
       "NOTIFY_FAILED before the subscriber looked: its process is signalled once and the next "
       "PUBLISH lists it again",
       2,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publish("p", "e1").lists({"w"}), quiet(1),
        notify_failed("p", "w"), signalled(1), notify_failed("p", "w"), quiet(1),
        publish("p", "e2").lists({"w"})}},
      {"NotifyFailedAfterItLookedDoesNothing",
       "NOTIFY_FAILED after the subscriber looked: no signal, the promise of the next listing "
       "stands",
       2,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publish("p", "e1").lists({"w"}),
        receive("w").gets({"e1"}), notify_failed("p", "w"), quiet(1),
        publish("p", "e2").lists({"w"}), publish("p", "e3").lists({})}},
      {"NotifyFailedCountsOnlyFromThePublishersProcess",
       "NOTIFY_FAILED through another process's publisher is refused and breaks nothing",
       3,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publish("p", "e1").lists({"w"}),
        notify_failed("p", "w").by(2), quiet(1), publish("p", "e2").lists({})}},
      {"PublisherDeathBeforeItLookedSignals",
       "the listing publisher's process dies before the subscriber looked: a signal, and "
       "another publisher's PUBLISH lists it again; the dead one's entries stay receivable",
       3,
       {subscriber(1, "w", wake_once), publisher(0, "p", 4), publisher(2, "q", 4),
        publish("p", "e1").lists({"w"}), publish("q", "e2").lists({}), kill(0), signalled(1),
        publish("q", "e3").lists({"w"}), receive("w").gets({"e1", "e2", "e3"})}},
      {"PublisherDeathAfterItLookedDoesNothing",
       "the listing publisher's process dies after the subscriber looked: no signal",
       3,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publisher(2, "q"),
        publish("p", "e1").lists({"w"}), receive("w").gets({"e1"}), kill(0), quiet(1),
        publish("q", "e2").lists({"w"})}},
      {"ThePromiseIsTheLatestListers",
       "a plain callback subscriber listed by two processes: the earlier one's death breaks "
       "nothing, the later one's does",
       3,
       {subscriber(1, "c", callback), publisher(0, "p"), publisher(2, "q"),
        publish("p", "e1").lists({"c"}), publish("q", "e2").lists({"c"}), kill(0), quiet(1),
        kill(2), signalled(1)}},
      {"WatchdogSignalsOncePerListing",
       "a callback subscriber, wake-once or not, that has not looked a watchdog period after "
       "its first listing has its process signalled, once, and is not listed again for it",
       3,
       {subscriber(1, "w", wake_once), subscriber(2, "c", callback), publisher(0, "p", 4),
        publish("p", "e1").lists({"c", "w"}), pass_watchdog(), signalled(1), signalled(2),
        publish("p", "e2").lists({"c"}), pass_watchdog(), quiet(1), quiet(2),
        receive("w").gets({"e1", "e2"}), receive("c").gets({"e1", "e2"}),
        publish("p", "e3").lists({"c", "w"}), pass_watchdog(), signalled(1), signalled(2)}},
      {"WatchdogLeavesAPromiseKept",
       "the watchdog signals only the subscriber that has not looked since its listing",
       3,
       {subscriber(1, "w", wake_once), subscriber(2, "c", callback), publisher(0, "p"),
        publish("p", "e1").lists({"c", "w"}), receive("w").gets({"e1"}), pass_watchdog(), quiet(1),
        signalled(2)}},
      {"PublishThroughAnotherProcesssPublisherIsRefused",
       "a PUBLISH through another process's publisher fails EPERM and lists no one",
       2,
       {subscriber(1, "w", wake_once), publisher(0, "p"), publish("p", "e1").by(1).fails(EPERM),
        counts("w", {}), publish("p", "e1").lists({"w"})}},
      {"WakeOnceIsForCallbackSubscribersOnly",
       "a polling subscriber or a publisher cannot be wake-once, and a publisher cannot poll",
       2,
       {subscriber(1, "x", Flavor{true, true}).fails(EINVAL),
        publisher(0, "y", 1, wake_once).fails(EINVAL),
        publisher(0, "z", 1, polling).fails(EINVAL)}},

      // Entries and their references.
      {"DepthOverflowDropsTheOldest",
       "a subscriber over its depth drops its oldest unreceived entry, counted as dropped",
       2,
       {subscriber(1, "s", callback, 2), publisher(0, "p", 4), publish("p", "e1"),
        publish("p", "e2"), publish("p", "e3"),
        counts("s", {.unreceived = 2, .held = 0, .received = 0, .dropped = 1}),
        receive("s").gets({"e2", "e3"}),
        counts("s", {.unreceived = 0, .held = 2, .received = 2, .dropped = 1})}},
      {"ReceiveReleasesAllOrNone",
       "a RECEIVE's release list is released whole or not at all, and then nothing is received",
       2,
       {subscriber(1, "s", callback), publisher(0, "p", 4), publish("p", "e1"), publish("p", "e2"),
        receive("s").gets({"e1", "e2"}), publish("p", "e3"),
        receive("s").releasing({"e1", "never"}).fails(ENOENT),
        receive("s").releasing({"e1", "e1"}).fails(ENOENT),
        counts("s", {.unreceived = 1, .held = 2, .received = 2}),
        receive("s").releasing({"e2", "e1"}).gets({"e3"}),
        counts("s", {.unreceived = 0, .held = 1, .received = 3})}},
      {"ReleaseOfAnEntryNotHeldReleasesNothing",
       "RELEASE naming an entry not held (never published, unreceived, listed twice, released "
       "already) fails ENOENT and releases none",
       2,
       {subscriber(1, "s", callback), publisher(0, "p", 4), publish("p", "e1"), publish("p", "e2"),
        receive("s").gets({"e1", "e2"}), publish("p", "e3"),
        release("s", {"e1", "never"}).fails(ENOENT), release("s", {"e3"}).fails(ENOENT),
        release("s", {"e2", "e2"}).fails(ENOENT),
        counts("s", {.unreceived = 1, .held = 2, .received = 2}), release("s", {"e2", "e1"}),
        counts("s", {.unreceived = 1, .held = 0, .received = 2}),
        release("s", {"e1"}).fails(ENOENT)}},
      {"ReclaimableOnlyOnceNothingReferencesIt",
       "an entry comes back to its publisher's process only once its window, every held and "
       "every unreceived reference let it go",
       2,
       {subscriber(1, "s", callback), subscriber(1, "q", polling), publisher(0, "p", 1),
        publish("p", "e1").reclaims({}), receive("s").gets({"e1"}), publish("p", "e2").reclaims({}),
        live_entries(2), release("s", {"e1"}), reclaim(0).reclaims({}), take("q").gets({"e2"}),
        reclaim(0).reclaims({"e1"}), live_entries(1), release("q", {"e2"}),
        release("s", {"e2"}).fails(ENOENT), receive("s").gets({"e2"}), release("s", {"e2"}),
        live_entries(1), publish("p", "e3").reclaims({"e2"}), live_entries(1)}},
      {"TakePassesOlderEntriesOver",
       "TAKE holds the newest unreceived entry and lets the older ones go, not counted as "
       "dropped",
       2,
       {subscriber(1, "q", polling, 4), publisher(0, "p", 1), publish("p", "e1"),
        publish("p", "e2"), publish("p", "e3").reclaims({}), take("q").gets({"e3"}),
        counts("q", {.unreceived = 0, .held = 1, .received = 1, .dropped = 0}), take("q").gets({}),
        reclaim(0).reclaims({"e1", "e2"}), live_entries(1)}},

      // Services' routes.
      {"ToOneReachesThatSubscriberAlone",
       "a PUBLISH to one subscriber gives the entry to it alone and lists it alone",
       3,
       {subscriber(1, "a", wake_once), subscriber(2, "b", wake_once), publisher(0, "p", 2),
        publish("p", "e1").to("b").lists({"b"}), receive("a").gets({}), receive("b").gets({"e1"}),
        counts("a", {}), counts("b", {.unreceived = 0, .held = 1, .received = 1, .dropped = 0}),
        publish("p", "e2").to("a").lists({"a"}), receive("b").gets({})}},
      {"ToOneOfAGoneSubscriberPublishesNothing",
       "a PUBLISH to a subscriber that is gone fails with ENXIO and leaves no entry",
       2,
       {subscriber(1, "a", wake_once), publisher(0, "p"), kill(1),
        publish("p", "e1").to("a").fails(ENXIO), live_entries(0)}},
      {"NoDropRefusesRatherThanDrop",
       "a PUBLISH without drops to a full subscriber fails with EAGAIN and drops nothing",
       2,
       {subscriber(1, "s", wake_once, 1), publisher(0, "p", 1),
        publish("p", "e1").without_drops().lists({"s"}),
        publish("p", "e2").without_drops().fails(EAGAIN),
        counts("s", {.unreceived = 1, .held = 0, .received = 0, .dropped = 0}), live_entries(1),
        receive("s").gets({"e1"}), publish("p", "e3").without_drops().lists({"s"})}},
      {"NoDropWithNobodyToGetItIsRefused",
       "a PUBLISH without drops that no subscriber would get fails with EPIPE",
       2,
       {publisher(0, "p"), publish("p", "e1").without_drops().fails(EPIPE), live_entries(0)}},
  };
  return table;
}

namespace {

using Clock = std::chrono::steady_clock;

// How long a promise may stand unkept before the watchdog, which acts up to
// a jiffy early, may have signalled where the scenario does not expect it.
constexpr auto promise_age_max = watchdog_period * 4 / 5;

std::string join(const std::vector<std::string>& names) {
  std::string text = "[";
  for (const std::string& name : names) text += (text.size() > 1 ? ", " : "") + name;
  return text + "]";
}

std::string describe(const Step& step) {
  const std::string by = " by process " + std::to_string(step.process);
  switch (step.kind) {
    case Step::Kind::publisher:
      return "process " + std::to_string(step.process) + " adds publisher " + step.endpoint;
    case Step::Kind::subscriber:
      return "process " + std::to_string(step.process) + " adds subscriber " + step.endpoint;
    case Step::Kind::publish:
      return "publish " + step.endpoint + " as " + step.entry +
             (step.subscriber.empty() ? "" : " to " + step.subscriber) +
             (step.no_drop ? " without drops" : "") + (step.process >= 0 ? by : "");
    case Step::Kind::notify_failed:
      return "notify_failed " + step.endpoint + " for " + step.subscriber +
             (step.process >= 0 ? by : "");
    case Step::Kind::receive:
      return "receive " + step.endpoint + (step.ids.empty() ? "" : " releasing " + join(step.ids));
    case Step::Kind::take:
      return "take " + step.endpoint;
    case Step::Kind::release:
      return "release " + join(step.ids) + " of " + step.endpoint;
    case Step::Kind::reclaim:
      return "reclaim" + by;
    case Step::Kind::counts:
      return "counters of " + step.endpoint;
    case Step::Kind::live_entries:
      return "live entries of the topic";
    case Step::Kind::signalled:
      return "wake eventfd of process " + std::to_string(step.process);
    case Step::Kind::kill:
      return "process " + std::to_string(step.process) + " dies";
    case Step::Kind::pass_watchdog:
      return "a watchdog period passes";
  }
  return "?";
}

std::string render(const Counts& counts) {
  return "{unreceived " + std::to_string(counts.unreceived) + ", held " +
         std::to_string(counts.held) + ", received " + std::to_string(counts.received) +
         ", dropped " + std::to_string(counts.dropped) + "}";
}

class Run {
 public:
  Run(const Scenario& scenario, World& world)
      : world_(world),
        topic_("/kernel_rules/" + scenario.name + "_" + std::to_string(::getpid())),
        next_offset_(static_cast<std::size_t>(scenario.processes), 0),
        alive_(static_cast<std::size_t>(scenario.processes), true) {}

  // Empty, or how the step differed from what it must give.
  std::string step(const Step& step) {
    switch (step.kind) {
      case Step::Kind::kill:
        world_.kill(step.process);
        alive_.at(static_cast<std::size_t>(step.process)) = false;
        age_promises();
        std::erase_if(promised_, [&](const auto& promise) {
          const auto found = endpoints_.find(promise.first);
          return found != endpoints_.end() && found->second.process == step.process;
        });
        return {};
      case Step::Kind::pass_watchdog:
        age_promises();
        world_.pass_watchdog();
        promised_.clear();  // signalled once, as the scenario expects
        return {};
      default:
        break;
    }
    const int process = acting(step);
    const Call call = resolve(step, process);
    const auto start = Clock::now();
    const Answer answer = world_.perform(process, call);
    age_promises();
    if (step.kind == Step::Kind::receive || step.kind == Step::Kind::take) {
      promised_.erase(step.endpoint);  // it looked
    }
    if (step.kind == Step::Kind::publish) {
      for (std::uint32_t i = 0; i < answer.wake_count; ++i) {
        promised_.emplace(subscriber_name(answer.wake_ids[i]), start);
      }
    }
    if ((step.kind == Step::Kind::publish && step.listed) || step.kind == Step::Kind::signalled) {
      observed_late_ = observed_late_ || watchdog_may_have_acted_;
    }
    if (answer.error != step.error) {
      return "gave " + errno_text(answer.error) + ", not " + errno_text(step.error);
    }
    if (answer.error) return {};
    return compare(step, process, call, answer);
  }

  // A listing or a signal was looked at after a promise had stood long
  // enough for the watchdog to act unasked: the run proves nothing.
  bool observed_late() const { return observed_late_; }

 private:
  struct Endpoint {
    EndpointId id;
    int process = 0;
    bool publisher = false;
  };
  struct Entry {
    std::uint64_t id = 0;
    std::uint64_t offset = 0;
    int process = 0;
  };

  static std::string errno_text(int err) {
    return err ? std::string(std::strerror(err)) + " (" + std::to_string(err) + ")" : "success";
  }

  const Endpoint& endpoint(const std::string& name) const {
    const auto found = endpoints_.find(name);
    if (found == endpoints_.end()) throw std::logic_error("the scenario names no endpoint " + name);
    return found->second;
  }

  int acting(const Step& step) const {
    if (step.process >= 0) return step.process;
    if (!step.endpoint.empty()) return endpoint(step.endpoint).process;
    const auto alive = std::find(alive_.begin(), alive_.end(), true);
    return static_cast<int>(alive - alive_.begin());
  }

  std::uint64_t entry_id(const std::string& name) {
    if (const auto found = entries_.find(name); found != entries_.end()) return found->second.id;
    // Never issued by either kernel.
    return never_issued_.emplace(name, (1ULL << 40) + never_issued_.size()).first->second;
  }

  Call resolve(const Step& step, int process) {
    Call call;
    std::strncpy(call.topic, topic_.c_str(), sizeof call.topic - 1);
    call.depth = step.depth;
    call.polling = step.flavor.polling;
    call.wake_once = step.flavor.wake_once;
    if (step.ids.size() > Call::ids_max) throw std::logic_error("too many ids in one step");
    for (const std::string& name : step.ids) call.ids[call.id_count++] = entry_id(name);
    switch (step.kind) {
      case Step::Kind::publisher:
        call.kind = Call::Kind::add_publisher;
        break;
      case Step::Kind::subscriber:
        call.kind = Call::Kind::add_subscriber;
        break;
      case Step::Kind::publish: {
        call.kind = Call::Kind::publish;
        call.endpoint = endpoint(step.endpoint).id;
        std::uint64_t& next = next_offset_.at(static_cast<std::size_t>(process));
        call.offset = next;
        next += 64;
        call.to_one = !step.subscriber.empty();
        if (call.to_one) call.subscriber_id = endpoint(step.subscriber).id.id;
        call.no_drop = step.no_drop;
        if (next > pool_block) throw std::logic_error("the scenario publishes too much");
        break;
      }
      case Step::Kind::notify_failed:
        call.kind = Call::Kind::notify_failed;
        call.endpoint = endpoint(step.endpoint).id;
        call.subscriber_id = endpoint(step.subscriber).id.id;
        break;
      case Step::Kind::receive:
        call.kind = Call::Kind::receive;
        call.endpoint = endpoint(step.endpoint).id;
        break;
      case Step::Kind::take:
        call.kind = Call::Kind::take;
        call.endpoint = endpoint(step.endpoint).id;
        break;
      case Step::Kind::release:
        call.kind = Call::Kind::release;
        call.endpoint = endpoint(step.endpoint).id;
        break;
      case Step::Kind::reclaim:
        call.kind = Call::Kind::reclaim;
        break;
      case Step::Kind::counts:
        call.kind = Call::Kind::counts;
        call.subscriber_id = endpoint(step.endpoint).id.id;
        break;
      case Step::Kind::live_entries:
        call.kind = Call::Kind::live_entries;
        break;
      case Step::Kind::signalled:
        call.kind = Call::Kind::wake_signalled;
        break;
      case Step::Kind::kill:
      case Step::Kind::pass_watchdog:
        throw std::logic_error("not a call");
    }
    return call;
  }

  std::string subscriber_name(std::uint32_t id) const {
    for (const auto& [name, found] : endpoints_) {
      if (!found.publisher && found.id.id == id) return name;
    }
    return "subscriber#" + std::to_string(id);
  }

  std::string entry_name(std::uint64_t id) const {
    for (const auto& [name, found] : entries_) {
      if (found.id == id) return name;
    }
    return "entry#" + std::to_string(id);
  }

  std::string reclaimed_name(int process, std::uint64_t offset) const {
    for (const auto& [name, found] : entries_) {
      if (found.process == process && found.offset == offset) return name;
    }
    return "offset#" + std::to_string(offset);
  }

  static std::string differ(const std::string& what, std::vector<std::string> got,
                            std::vector<std::string> expected, bool ordered) {
    if (!ordered) {
      std::sort(got.begin(), got.end());
      std::sort(expected.begin(), expected.end());
    }
    if (got == expected) return {};
    return what + " " + join(got) + ", not " + join(expected);
  }

  std::string compare(const Step& step, int process, const Call& call, const Answer& answer) {
    switch (step.kind) {
      case Step::Kind::publisher:
      case Step::Kind::subscriber:
        endpoints_[step.endpoint] =
            Endpoint{answer.endpoint, process, step.kind == Step::Kind::publisher};
        return {};
      case Step::Kind::publish: {
        entries_[step.entry] = Entry{answer.entry_id, call.offset, process};
        std::vector<std::string> listed;
        for (std::uint32_t i = 0; i < answer.wake_count; ++i) {
          listed.push_back(subscriber_name(answer.wake_ids[i]));
        }
        if (step.listed) {
          if (auto wrong = differ("listed", listed, *step.listed, false); !wrong.empty()) {
            return wrong;
          }
        }
        return compare_reclaimed(step, process, answer);
      }
      case Step::Kind::receive:
      case Step::Kind::take: {
        if (!step.got) return {};
        std::vector<std::string> got;
        for (std::uint32_t i = 0; i < answer.entry_count; ++i) {
          got.push_back(entry_name(answer.entry_ids[i]));
        }
        return differ("got", got, *step.got, true);
      }
      case Step::Kind::reclaim:
        return compare_reclaimed(step, process, answer);
      case Step::Kind::counts:
        if (answer.counts == *step.counts) return {};
        return "counted " + render(answer.counts) + ", not " + render(*step.counts);
      case Step::Kind::live_entries:
        if (answer.live_entries == step.live) return {};
        return "counted " + std::to_string(answer.live_entries) + " live entries, not " +
               std::to_string(step.live);
      case Step::Kind::signalled:
        if (answer.signalled == step.signalled) return {};
        return answer.signalled ? "signalled" : "not signalled";
      default:
        return {};
    }
  }

  std::string compare_reclaimed(const Step& step, int process, const Answer& answer) const {
    if (!step.reclaimed) return {};
    std::vector<std::string> reclaimed;
    for (std::uint32_t i = 0; i < answer.reclaim_count; ++i) {
      reclaimed.push_back(reclaimed_name(process, answer.reclaimed[i]));
    }
    return differ("reclaimed", reclaimed, *step.reclaimed, false);
  }

  void age_promises() {
    const auto now = Clock::now();
    for (const auto& [name, since] : promised_) {
      if (now - since > promise_age_max) watchdog_may_have_acted_ = true;
    }
  }

  World& world_;
  std::string topic_;
  std::vector<std::uint64_t> next_offset_;  // per process
  std::vector<bool> alive_;
  std::map<std::string, Endpoint> endpoints_;
  std::map<std::string, Entry> entries_;
  std::map<std::string, std::uint64_t> never_issued_;
  // Subscribers listed since they last looked, and when first listed.
  std::map<std::string, Clock::time_point> promised_;
  bool watchdog_may_have_acted_ = false;
  bool observed_late_ = false;
};

struct Outcome {
  std::string failure;
  bool slow = false;
};

Outcome run(const Scenario& scenario, World& world) {
  Run run(scenario, world);
  for (std::size_t i = 0; i < scenario.steps.size(); ++i) {
    const Step& step = scenario.steps[i];
    const std::string failure = run.step(step);
    if (failure.empty() && !run.observed_late()) continue;
    std::ostringstream text;
    text << "step " << i + 1 << " (" << describe(step)
         << "): " << (failure.empty() ? "as expected" : failure);
    if (run.observed_late()) {
      text << ", but a promise had stood over "
           << std::chrono::milliseconds(promise_age_max).count() << " ms before";
    }
    return {text.str(), run.observed_late()};
  }
  return {};
}

}  // namespace

std::string check(const Scenario& scenario, const MakeWorld& make_world, int* runs) {
  constexpr int attempts = 4;
  std::string last;
  for (int attempt = 1; attempt <= attempts; ++attempt) {
    if (runs) *runs = attempt;
    Outcome outcome;
    try {
      const std::unique_ptr<World> world = make_world(scenario.processes);
      outcome = run(scenario, *world);
    } catch (const std::exception& error) {
      return std::string("the world failed: ") + error.what();
    }
    if (!outcome.slow) return outcome.failure;
    last = outcome.failure;
  }
  return "every one of " + std::to_string(attempts) + " runs was too slow to judge; the last, " +
         last;
}

}  // namespace agnocast::detail::kernel_rules
