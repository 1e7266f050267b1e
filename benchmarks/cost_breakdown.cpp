// agnocast-bench-breakdown: where one 64 B message's time goes.  Run by
// agnocast-bench in icount mode, where guest time is instructions executed,
// so a duration is a cost.  It times, in place (call_timer.hpp), every call
// libagnocast makes on each side of a one-message-at-a-time run like the
// latency series, the library's own user-space time between them, and, in
// loops in the same boot, reference calls: a null ioctl
// (AGNOCAST_IOC_GET_VERSION), getppid() and a non-blocking mq_send,
// mq_receive and epoll_wait.  Prints one JSON object.  With --service it
// times a service's 64 B request → response round trip instead, call by call
// on the client and on the server, as run_agnocast_round_trip runs it.
#include <agnocast.h>
#include <fcntl.h>
#include <mqueue.h>
#include <sys/epoll.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <agnocast/agnocast.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "bench_service.hpp"
#include "bench_support.hpp"
#include "call_timer.hpp"

namespace agnocast::bench {
namespace {

struct BreakdownMessage {
  std::uint64_t seq = 0;
  agnocast::vector<std::uint8_t> payload;
};

}  // namespace
}  // namespace agnocast::bench

AGNOCAST_MESSAGE(agnocast::bench::BreakdownMessage, "agnocast_bench/msg/BreakdownMessage", seq,
                 payload);

namespace agnocast::bench {
namespace {

using json = nlohmann::ordered_json;

// The benchmark's own spans on the timeline.
enum Mark : std::int64_t {
  borrow = 1,
  publish = 2,
  callback = 3,
  send_request = 4,
  response_callback = 5,
  serve = 6
};

double median_of(std::vector<std::int64_t> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return static_cast<double>(values[(values.size() - 1) / 2]);
}

// Median duration of each name's calls recorded while `body` ran `rounds` times.
template <typename Body>
std::map<std::string, double> recorded_loop(std::size_t rounds, Body body) {
  start_recording(rounds * 4);
  for (std::size_t i = 0; i < rounds; ++i) body();
  stop_recording();
  std::map<std::string, std::vector<std::int64_t>> durations;
  for (const TimedCall& call : recorded_calls()) {
    durations[call_name(call)].push_back(call.end_ns - call.start_ns);
  }
  std::map<std::string, double> medians;
  for (auto& [name, values] : durations) {
    if (values.size() != rounds) throw std::runtime_error("reference loop of " + name + " failed");
    medians[name] = median_of(values);
  }
  return medians;
}

void check(bool ok, const char* what) {
  if (!ok) throw std::system_error(errno, std::generic_category(), what);
}

// Each reference timed like the library's calls: two clock reads around the
// raw call, the median of `rounds`.
json references(std::size_t rounds) {
  json result;
  result["clock_read_ns"] = recorded_loop(rounds, [] {
    const std::int64_t start = now_ns();
    mark(0, start, now_ns());
  })["mark"];
  const int device = ::open(AGNOCAST_DEVICE_PATH, O_RDONLY | O_CLOEXEC);
  check(device >= 0, AGNOCAST_DEVICE_PATH);
  agnocast_version version{};
  result["null_ioctl_ns"] = recorded_loop(rounds, [&] {
    check(::ioctl(device, AGNOCAST_IOC_GET_VERSION, &version) == 0, "GET_VERSION");
  })["ioctl GET_VERSION"];
  ::close(device);
  result["getppid_ns"] = recorded_loop(rounds, [] {
    const std::int64_t start = now_ns();
    syscall(SYS_getppid);
    mark(0, start, now_ns());
  })["mark"];

  const std::string name = "/agnocast-bench-breakdown-" + std::to_string(getpid());
  mq_attr attributes{};
  attributes.mq_maxmsg = 1;
  attributes.mq_msgsize = sizeof(std::uint64_t);
  const mqd_t queue = mq_open(name.c_str(), O_RDWR | O_CREAT | O_NONBLOCK, 0600, &attributes);
  check(queue != static_cast<mqd_t>(-1), "mq_open");
  const int epoll_fd = epoll_create1(EPOLL_CLOEXEC);
  epoll_event event{};
  event.events = EPOLLIN;
  check(epoll_fd >= 0 && epoll_ctl(epoll_fd, EPOLL_CTL_ADD, queue, &event) == 0, "epoll_ctl");
  std::uint64_t word = 1;
  // A message sent, the queue seen ready, the message received: each call
  // without sleeping, as on the hot path once the subscriber is awake.
  auto loop = recorded_loop(rounds, [&] {
    check(mq_send(queue, reinterpret_cast<const char*>(&word), sizeof word, 0) == 0, "mq_send");
    check(epoll_wait(epoll_fd, &event, 1, 0) == 1, "epoll_wait");
    check(mq_receive(queue, reinterpret_cast<char*>(&word), sizeof word, nullptr) >= 0,
          "mq_receive");
  });
  result["mq_send_ns"] = loop["mq_send"];
  result["epoll_wait_ready_ns"] = loop["epoll_wait (poll)"];
  result["mq_receive_ns"] = loop["mq_receive"];
  ::close(epoll_fd);
  mq_close(queue);
  mq_unlink(name.c_str());
  return result;
}

template <typename Body>
pid_t spawn(Body body) {
  const pid_t child = fork();
  check(child >= 0, "fork");
  if (child == 0) {
    int status = 1;
    try {
      status = body();
    } catch (const std::exception& error) {
      std::cerr << "agnocast-bench-breakdown: " << error.what() << "\n";
    }
    _exit(status);
  }
  return child;
}

void reap(pid_t child) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("a breakdown role failed");
  }
}

void send_calls(int fd) {
  std::vector<std::int64_t> flat;
  for (const TimedCall& call : recorded_calls()) {
    flat.insert(flat.end(),
                {static_cast<std::int64_t>(call.kind), call.detail, call.start_ns, call.end_ns});
  }
  send_latencies(fd, flat);
}

std::vector<TimedCall> receive_calls(int fd) {
  const std::vector<std::int64_t> flat = receive_latencies(fd);
  std::vector<TimedCall> calls;
  for (std::size_t i = 0; i + 3 < flat.size(); i += 4) {
    calls.push_back({static_cast<CallKind>(flat[i]), flat[i + 1], flat[i + 2], flat[i + 3]});
  }
  return calls;
}

struct Sides {
  std::vector<TimedCall> publisher;
  std::vector<TimedCall> subscriber;
};

// One message at a time, as in the latency series: the publisher borrows,
// writes 64 B, publishes and waits for the subscriber's ack, then pauses so
// that both sides sleep before the next one.  Both record every call after
// the warm-up.
Sides run_scenario(std::size_t warmup, std::size_t count) {
  const std::string topic = "/bench/breakdown_" + std::to_string(getpid());
  const std::size_t total = warmup + count;
  Pipe ready = Pipe::open(), ack = Pipe::open(), publisher_calls = Pipe::open(),
       subscriber_calls = Pipe::open();
  const pid_t subscriber = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_breakdown_subscriber"};
    std::size_t received = 0;
    auto subscription = node.create_subscription<BreakdownMessage>(
        topic, agnocast::QoS{10}, [&](const agnocast::ipc_shared_ptr<const BreakdownMessage>& m) {
          const std::int64_t t1 = now_ns();
          if (m->seq + 1 == warmup) start_recording(count * 64);
          char byte = 1;
          write_all(ack.write_fd, &byte, 1);
          if (++received == total) executor.cancel();
          mark(Mark::callback, t1, now_ns());
        });
    executor.add_node(node);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    stop_recording();
    send_calls(subscriber_calls.write_fd);
    return 0;
  });
  const pid_t publisher = spawn([&] {
    agnocast::Node node{"bench_breakdown_publisher"};
    auto pub = node.create_publisher<BreakdownMessage>(topic, agnocast::QoS{10});
    char byte = 0;
    if (!read_all(ready.read_fd, &byte, 1)) return 1;
    for (std::size_t seq = 0; seq < total; ++seq) {
      if (seq == warmup) start_recording(count * 64);
      const std::int64_t b0 = now_ns();
      auto message = pub->borrow_loaned_message();
      const std::int64_t b1 = now_ns();
      message->payload.resize(64);
      fill_payload(std::span(message->payload.data(), 64), seq);
      message->seq = seq;
      const std::int64_t p0 = now_ns();
      pub->publish(std::move(message));
      const std::int64_t p1 = now_ns();
      mark(Mark::borrow, b0, b1);
      mark(Mark::publish, p0, p1);
      if (!read_all(ack.read_fd, &byte, 1)) return 1;
      settle_between_messages();
    }
    stop_recording();
    send_calls(publisher_calls.write_fd);
    return 0;
  });
  publisher_calls.close_write();
  subscriber_calls.close_write();
  Sides sides{receive_calls(publisher_calls.read_fd), receive_calls(subscriber_calls.read_fd)};
  reap(publisher);
  reap(subscriber);
  return sides;
}

bool is_mark(const TimedCall& call, Mark what) {
  return call.kind == CallKind::mark && call.detail == what;
}
bool is_wait(const TimedCall& call) {
  return call.kind == CallKind::epoll_wait && call.detail != 0;
}

// What one side did in its measured spans over all messages.
struct SideCosts {
  std::map<std::string, std::vector<std::int64_t>> calls;  // durations, by name
  std::vector<std::int64_t> library_ns;                    // per message
  std::size_t messages = 0;

  void add_calls_within(const std::vector<TimedCall>& all, std::int64_t from, std::int64_t to,
                        std::int64_t& in_calls) {
    for (const TimedCall& call : all) {
      if (call.kind == CallKind::mark || call.start_ns < from || call.end_ns > to) continue;
      calls[call_name(call)].push_back(call.end_ns - call.start_ns);
      in_calls += call.end_ns - call.start_ns;
    }
  }

  json to_json(const char* blocking_note) const {
    json list = json::array();
    for (const auto& [name, durations] : calls) {
      list.push_back(
          {{"name", name},
           {"per_message", static_cast<double>(durations.size()) / static_cast<double>(messages)},
           {"ns", median_of(durations)}});
    }
    json side = {{"calls", list}, {"library_ns", median_of(library_ns)}};
    if (blocking_note) side["blocking_wait"] = blocking_note;
    return side;
  }
};

json analyse(const Sides& sides) {
  // Publisher: borrow_loaned_message() and publish(), less the calls in them.
  SideCosts publisher;
  std::vector<const TimedCall*> publishes;
  std::vector<std::int64_t> send_ends;
  for (std::size_t i = 0; i < sides.publisher.size(); ++i) {
    const TimedCall& call = sides.publisher[i];
    if (is_mark(call, Mark::publish)) publishes.push_back(&call);
    if (!is_mark(call, Mark::borrow)) continue;
    const TimedCall* published = nullptr;
    for (std::size_t j = i + 1; j < sides.publisher.size() && !published; ++j) {
      if (is_mark(sides.publisher[j], Mark::publish)) published = &sides.publisher[j];
    }
    if (!published) break;
    std::int64_t in_calls = 0;
    publisher.add_calls_within(sides.publisher, call.start_ns, call.end_ns, in_calls);
    publisher.add_calls_within(sides.publisher, published->start_ns, published->end_ns, in_calls);
    publisher.library_ns.push_back((call.end_ns - call.start_ns) +
                                   (published->end_ns - published->start_ns) - in_calls);
    ++publisher.messages;
    std::int64_t last_send = published->start_ns;
    for (const TimedCall& other : sides.publisher) {
      if (other.kind == CallKind::mq_send && other.start_ns >= published->start_ns &&
          other.end_ns <= published->end_ns) {
        last_send = other.end_ns;
      }
    }
    send_ends.push_back(last_send);
  }

  // Subscriber: from the return of the wait that woke it to the callback,
  // and from the callback's end to the next wait, less the calls in them.
  SideCosts subscriber;
  std::vector<std::int64_t> to_callback, after_callback, callback_starts, wakes;
  const auto& sub = sides.subscriber;
  for (std::size_t i = 0; i < sub.size(); ++i) {
    if (!is_mark(sub[i], Mark::callback)) continue;
    std::int64_t woke = -1, slept = -1;
    for (std::size_t j = i; j-- > 0;) {
      if (is_wait(sub[j])) {
        woke = sub[j].end_ns;
        break;
      }
    }
    for (std::size_t j = i + 1; j < sub.size(); ++j) {
      if (is_wait(sub[j])) {
        slept = sub[j].start_ns;
        break;
      }
    }
    if (woke < 0 || slept < 0) continue;
    std::int64_t in_calls = 0;
    subscriber.add_calls_within(sub, woke, sub[i].start_ns, in_calls);
    subscriber.add_calls_within(sub, sub[i].end_ns, slept, in_calls);
    to_callback.push_back(sub[i].start_ns - woke);
    after_callback.push_back(slept - sub[i].end_ns);
    subscriber.library_ns.push_back(to_callback.back() + after_callback.back() - in_calls);
    callback_starts.push_back(sub[i].start_ns);
    wakes.push_back(woke);
    ++subscriber.messages;
  }
  std::size_t waits = 0;
  for (const TimedCall& call : sub) waits += is_wait(call) ? 1 : 0;

  // Message k of each side is the same message: one is in flight at a time.
  const std::size_t messages = std::min(publishes.size(), callback_starts.size());
  if (messages == 0 || send_ends.size() < messages) {
    throw std::runtime_error("the breakdown recorded no whole message");
  }
  std::vector<std::int64_t> latencies, handoffs;
  for (std::size_t k = 0; k < messages; ++k) {
    latencies.push_back(callback_starts[k] - publishes[k]->start_ns);
    handoffs.push_back(wakes[k] - send_ends[k]);
  }
  char note[96];
  std::snprintf(note, sizeof note, "epoll_wait, %.2f per message, asleep: not timed",
                static_cast<double>(waits) / static_cast<double>(subscriber.messages));

  // The message of median latency, both sides' calls on one timeline from
  // its publish() call to the subscriber's next wait.
  std::vector<std::size_t> order(messages);
  for (std::size_t k = 0; k < messages; ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return latencies[a] < latencies[b]; });
  const std::size_t typical = order[(messages - 1) / 2];
  const std::int64_t t0 = publishes[typical]->start_ns;
  const std::int64_t until = callback_starts[typical] + 1'000'000;
  std::vector<std::pair<const TimedCall*, const char*>> spans;
  // The wait that woke the subscriber began before t0: its return, as a point.
  const TimedCall woke{CallKind::epoll_wait, -2, wakes[typical], wakes[typical]};
  spans.emplace_back(&woke, "subscriber");
  for (const TimedCall& call : sides.publisher) {
    if (call.start_ns >= t0 && call.start_ns < callback_starts[typical]) {
      spans.emplace_back(&call, "publisher");
    }
  }
  bool asleep_again = false;
  for (const TimedCall& call : sub) {
    if (asleep_again || call.start_ns < wakes[typical] || call.start_ns > until) continue;
    spans.emplace_back(&call, "subscriber");
    asleep_again = call.start_ns > callback_starts[typical] && is_wait(call);
  }
  std::sort(spans.begin(), spans.end(),
            [](const auto& a, const auto& b) { return a.first->start_ns < b.first->start_ns; });
  json timeline = json::array();
  for (const auto& [call, side] : spans) {
    std::string what = call_name(*call);
    if (call == &woke) what = "epoll_wait returns";
    if (call->kind == CallKind::mark) {
      what = call->detail == Mark::publish    ? "publish()"
             : call->detail == Mark::callback ? "callback"
                                              : "borrow_loaned_message()";
    }
    timeline.push_back({{"side", side},
                        {"what", what},
                        {"start_ns", call->start_ns - t0},
                        {"end_ns", call->end_ns - t0}});
  }

  return {{"messages", messages},
          {"latency_ns", median_of(latencies)},
          {"publisher", publisher.to_json(nullptr)},
          {"subscriber", subscriber.to_json(note)},
          {"wake_to_callback_ns", median_of(to_callback)},
          {"after_callback_ns", median_of(after_callback)},
          {"handoff_ns", median_of(handoffs)},
          {"timeline", timeline}};
}

// One 64 B request in flight at a time, as in the round-trip series: the
// client writes it, sends it and spins until its response callback runs,
// then pauses; the server answers from its callback with a response written
// before the first request.  Both record every call after the warm-up.
Sides run_service_scenario(std::size_t warmup, std::size_t count) {
  const std::string name = "/bench/breakdown_service_" + std::to_string(getpid());
  const std::size_t total = warmup + count;
  Pipe ready = Pipe::open(), stop = Pipe::open(), client_calls = Pipe::open(),
       server_calls = Pipe::open();
  const pid_t server = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_breakdown_server"};
    std::vector<agnocast::ipc_shared_ptr<BenchResponse>> responses;
    std::size_t answered = 0;
    auto service = node.create_service<BenchService>(
        name, [&](std::shared_ptr<agnocast::Service<BenchService>> serving, agnocast::RequestId id,
                  agnocast::ipc_shared_ptr<const BenchRequest>) {
          const std::int64_t t = now_ns();
          serving->send_response(id, std::move(responses.at(answered)));
          mark(Mark::serve, t, now_ns());
          if (++answered == warmup) start_recording(count * 64);
        });
    for (std::size_t seq = 0; seq < total; ++seq) {
      auto response = service->borrow_loaned_response();
      response->payload.resize(64);
      responses.push_back(std::move(response));
    }
    executor.add_fd(stop.read_fd, [&] { executor.cancel(); });
    executor.add_node(node);
    char byte = 1;
    write_all(ready.write_fd, &byte, 1);
    executor.spin();
    stop_recording();
    send_calls(server_calls.write_fd);
    return 0;
  });
  const pid_t client = spawn([&] {
    agnocast::SingleThreadedExecutor executor;
    agnocast::Node node{"bench_breakdown_client"};
    auto caller = node.create_client<BenchService>(name);
    char byte = 0;
    if (!read_all(ready.read_fd, &byte, 1)) return 1;
    if (!caller->wait_for_service(std::chrono::seconds(60))) return 1;
    executor.add_node(node);
    for (std::size_t seq = 0; seq < total; ++seq) {
      if (seq == warmup) start_recording(count * 64);
      auto request = caller->borrow_loaned_request();
      request->seq = seq;
      request->payload.resize(64);
      fill_payload(std::span(request->payload.data(), 64), seq);
      bool answered = false;
      const std::int64_t t0 = now_ns();
      caller->async_send_request(std::move(request),
                                 [&](agnocast::Client<BenchService>::SharedFuture future) {
                                   const std::int64_t t1 = now_ns();
                                   answered = future.valid();
                                   mark(Mark::response_callback, t1, t1);
                                 });
      mark(Mark::send_request, t0, now_ns());
      while (!answered) {
        if (!executor.spin_once(std::chrono::seconds(60))) return 1;
      }
      settle_between_messages();
    }
    stop_recording();
    byte = 1;
    write_all(stop.write_fd, &byte, 1);
    send_calls(client_calls.write_fd);
    return 0;
  });
  client_calls.close_write();
  server_calls.close_write();
  Sides sides{receive_calls(client_calls.read_fd), receive_calls(server_calls.read_fd)};
  reap(client);
  reap(server);
  return sides;
}

// The round trips' windows: per side, the calls made in each window and the
// library's own time (the side's running time in the window less its
// calls); what is left of a window is neither side running in user space or
// in a timed call: the wake-ups' context switches.  `sides.publisher` holds
// the client, `sides.subscriber` the server.
json analyse_service(const Sides& sides) {
  const auto& client = sides.publisher;
  const auto& server = sides.subscriber;
  std::vector<const TimedCall*> sends, answers, serves;
  for (const TimedCall& call : client) {
    if (is_mark(call, Mark::send_request)) sends.push_back(&call);
    if (is_mark(call, Mark::response_callback)) answers.push_back(&call);
  }
  for (const TimedCall& call : server) {
    if (is_mark(call, Mark::serve)) serves.push_back(&call);
  }
  const std::size_t messages = std::min({sends.size(), answers.size(), serves.size()});
  if (messages == 0) throw std::runtime_error("the service breakdown recorded no whole round trip");
  // A side's running spans in [from, to]: between the returns of its blocking
  // waits and the starts of the next ones.
  auto running = [](const std::vector<TimedCall>& calls, std::int64_t from, std::int64_t to) {
    std::vector<std::pair<std::int64_t, std::int64_t>> spans;
    std::int64_t start = from;
    bool awake = true;
    for (const TimedCall& call : calls) {
      if (!is_wait(call) || call.end_ns < from || call.start_ns > to) continue;
      if (awake && call.start_ns >= start) spans.emplace_back(start, call.start_ns);
      start = call.end_ns;
      awake = call.end_ns <= to;
    }
    if (awake && start < to) spans.emplace_back(start, to);
    return spans;
  };
  SideCosts client_costs, server_costs;
  std::vector<std::int64_t> round_trips, switches;
  for (std::size_t k = 0; k < messages; ++k) {
    const std::int64_t t0 = sends[k]->start_ns, t1 = answers[k]->start_ns;
    round_trips.push_back(t1 - t0);
    std::int64_t accounted = 0;
    for (auto [side, calls] :
         {std::pair{&client_costs, &client}, std::pair{&server_costs, &server}}) {
      std::int64_t run = 0, in_calls = 0;
      for (const auto& [from, to] : running(*calls, t0, t1)) {
        run += to - from;
        side->add_calls_within(*calls, from, to, in_calls);
      }
      side->library_ns.push_back(run - in_calls);
      ++side->messages;
      accounted += run;
    }
    switches.push_back(t1 - t0 - accounted);
  }

  // The round trip of median time, both sides' calls on one timeline.
  std::vector<std::size_t> order(messages);
  for (std::size_t k = 0; k < messages; ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return round_trips[a] < round_trips[b]; });
  const std::size_t typical = order[(messages - 1) / 2];
  const std::int64_t t0 = sends[typical]->start_ns, t1 = answers[typical]->start_ns;
  json timeline = json::array();
  std::vector<std::pair<const TimedCall*, const char*>> spans;
  for (const TimedCall& call : client) {
    if (call.end_ns >= t0 && call.start_ns <= t1) spans.emplace_back(&call, "client");
  }
  for (const TimedCall& call : server) {
    if (call.end_ns >= t0 && call.start_ns <= t1) spans.emplace_back(&call, "server");
  }
  std::sort(spans.begin(), spans.end(),
            [](const auto& a, const auto& b) { return a.first->start_ns < b.first->start_ns; });
  for (const auto& [call, side] : spans) {
    std::string what = call_name(*call);
    if (call->kind == CallKind::mark) {
      what = call->detail == Mark::send_request ? "async_send_request()"
             : call->detail == Mark::serve      ? "server's callback"
                                                : "response callback";
    }
    // A wait that began before the window: only its return is in it.
    const std::int64_t start = std::max(call->start_ns, t0);
    timeline.push_back(
        {{"side", side}, {"what", what}, {"start_ns", start - t0}, {"end_ns", call->end_ns - t0}});
  }
  return {{"messages", messages},
          {"round_trip_ns", median_of(round_trips)},
          {"client", client_costs.to_json(nullptr)},
          {"server", server_costs.to_json(nullptr)},
          {"switches_ns", median_of(switches)},
          {"timeline", timeline}};
}

}  // namespace
}  // namespace agnocast::bench

int main(int argc, char** argv) {
  namespace bench = agnocast::bench;
  CLI::App app{"agnocast-bench-breakdown: the cost of one 64 B message, call by call"};
  std::size_t count = 50, warmup = 10, rounds = 50;
  app.add_option("--count", count, "messages recorded")->check(CLI::Range(1, 100000));
  app.add_option("--warmup", warmup, "messages before the recorded ones")
      ->check(CLI::Range(1, 1000));
  app.add_option("--rounds", rounds, "calls of each reference loop")->check(CLI::Range(1, 100000));
  bool service = false;
  app.add_flag("--service", service,
               "a service's 64 B round trip instead of a message, without the references");
  CLI11_PARSE(app, argc, argv);
  try {
    if (service) {
      std::cout << bench::analyse_service(bench::run_service_scenario(warmup, count)).dump()
                << "\n";
      return 0;
    }
    nlohmann::ordered_json result = bench::analyse(bench::run_scenario(warmup, count));
    result["reference"] = bench::references(rounds);
    std::cout << result.dump() << "\n";
  } catch (const std::exception& error) {
    std::cerr << "agnocast-bench-breakdown: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
