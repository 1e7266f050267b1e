#!/usr/bin/env python3
"""libagnocast's LTTng-UST events, as a reader nobody here wrote sees them.

Runs agnocast_trace_workload (a timer publishing on topic _a, a relay
publishing each message again on _b, a sink) in an LTTng session, reads the
trace with babeltrace2 and checks that every event has its fields and that
each publish can be followed, by entry id, to the take and the callback it
caused; and, in the same session, one test of the allocation hook, whose
heap scopes must each be entered and left once; and the workload again with
AGNOCAST_LTTNG=0, which must send nothing.  Then the workload once more,
with a session started only after it made its nodes, endpoints, timer and
executor: the library sends their init events again for it, so the same
checks hold.  Starts a session daemon when none runs, and stops it again.
usage: lttng_events_test.py TRACE_WORKLOAD [HEAPHOOK_TESTS]
(a sanitized build has no HEAPHOOK_TESTS: the sanitizer's malloc comes first)
"""
import collections
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

MESSAGES = 25
EVENT = re.compile(r"^\[(\d+\.\d+)\] \S+ agnocast:(\w+): (.*)$")
FIELD = re.compile(r'(\w+) = ("(?:[^"\\]|\\.)*"|[^,}\s]+)')

failures = []
context = ""  # which recording the checks are of


def check(condition, what):
    if not condition:
        failures.append(context + what)
    return condition


def lttng(*args):
    result = subprocess.run(["lttng", *args], capture_output=True, text=True, timeout=60)
    if result.returncode != 0:
        sys.exit(f"FAIL: lttng {' '.join(args)}: {result.stdout}{result.stderr}")


def session_daemons():
    result = subprocess.run(["pgrep", "-x", "lttng-sessiond"], capture_output=True, text=True)
    return {int(pid) for pid in result.stdout.split()}


def parse(text):
    events = []
    for line in text.splitlines():
        match = EVENT.match(line)
        if not match:
            continue
        fields = {}
        for key, value in FIELD.findall(match.group(3)):
            if value.startswith('"'):
                fields[key] = value[1:-1]
            else:
                fields[key] = int(value, 0)
        events.append((float(match.group(1)), match.group(2), fields))
    return events


HEAP_TEST = "HeapHookTest.TheScopeEndsAtPublishAndWhenALoanIsDropped"


def record(workload, heaphook_tests, output):
    session = f"agnocast_events_{os.getpid()}"
    lttng("create", session, f"--output={output}")
    try:
        lttng("enable-event", "--userspace", "agnocast:*", f"--session={session}")
        lttng("add-context", "--userspace", "--type=vpid", "--type=vtid", f"--session={session}")
        lttng("start", session)
        run = subprocess.run([workload, str(MESSAGES)], capture_output=True, text=True, timeout=60)
        print(run.stdout + run.stderr, end="")
        check(run.returncode == 0, f"the workload failed (exit {run.returncode})")
        if heaphook_tests:
            hook = subprocess.run([heaphook_tests, f"--gtest_filter={HEAP_TEST}"],
                                  capture_output=True, text=True, timeout=60)
            check(hook.returncode == 0, f"{HEAP_TEST} failed: {hook.stdout}{hook.stderr}")
        # Asked not to load the probes, though a session daemon listens.
        quiet = subprocess.Popen([workload, "5"], env={**os.environ, "AGNOCAST_LTTNG": "0"},
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        check(quiet.wait(timeout=60) == 0, "the workload with AGNOCAST_LTTNG=0 failed")
        lttng("stop", session)
        return quiet.pid
    finally:
        subprocess.run(["lttng", "destroy", session], capture_output=True, timeout=60)


def record_late(workload, output):
    """The workload made everything before this session started."""
    session = f"agnocast_events_late_{os.getpid()}"
    late = subprocess.Popen([workload, str(MESSAGES), "--late"], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    try:
        check(late.stdout.readline().strip() == "ready", "the late workload did not get ready")
        lttng("create", session, f"--output={output}")
        lttng("enable-event", "--userspace", "agnocast:*", f"--session={session}")
        lttng("add-context", "--userspace", "--type=vpid", "--type=vtid", f"--session={session}")
        lttng("start", session)
        late.stdin.write("go\n")
        late.stdin.flush()
        check(late.wait(timeout=60) == 0, f"the late workload failed (exit {late.returncode})")
        lttng("stop", session)
    finally:
        if late.poll() is None:
            late.kill()
        subprocess.run(["lttng", "destroy", session], capture_output=True, timeout=60)


def read_trace(output):
    text = subprocess.run(["babeltrace2", "--clock-seconds", "--no-delta", output],
                          capture_output=True, text=True, timeout=120, check=True).stdout
    return parse(text)


def verify_heap_scopes(events):
    """The hook's test process: every scope entered is left once, on its token."""
    pids = {f["vpid"] for _, n, f in events if n == "agnocast_heap_scope_enter"}
    if not check(len(pids) == 1, f"heap scopes entered by {len(pids)} processes, not 1"):
        return
    pid = pids.pop()
    open_scopes = collections.Counter()
    entered = 0
    for _, name, f in events:
        if f["vpid"] != pid:
            continue
        if name == "agnocast_heap_scope_enter":
            check(f["scope"] != 0, "a heap scope without its token")
            open_scopes[f["scope"]] += 1
            entered += 1
        elif name == "agnocast_heap_scope_exit":
            check(open_scopes[f["scope"]] > 0, f"heap scope {f['scope']:#x} left, never entered")
            open_scopes[f["scope"]] -= 1
    check(entered >= 2, f"{entered} heap scopes entered, not 2 at least (publish, drop)")
    check(not +open_scopes, f"heap scopes never left: {dict(+open_scopes)}")
    print(f"heap scopes: {entered} entered and left")


def verify(events):
    # The workload's process alone; the hook's test is verify_heap_scopes()'.
    scoped = {f["vpid"] for _, n, f in events if n == "agnocast_heap_scope_enter"}
    events = [e for e in events if e[2].get("vpid") not in scoped]
    by_name = collections.Counter(name for _, name, _ in events)
    print("events:", ", ".join(f"{name} {count}" for name, count in sorted(by_name.items())))
    for time_, name, fields in events:
        if not (check("vpid" in fields and "vtid" in fields, f"{name} without vpid/vtid")):
            return

    nodes = {f["node_handle"]: f["node_name"] for _, n, f in events if n == "agnocast_node_init"}
    check(sorted(nodes.values()) == ["relay", "sink", "source"], f"node_init names: {nodes}")
    groups = {f["callback_group"]: f for _, n, f in events if n == "agnocast_callback_group_init"}
    check(len(groups) >= 3 and all(g["node_handle"] in nodes for g in groups.values()),
          "a callback group per node, each naming its node")
    check(by_name["agnocast_construct_executor"] == 1 and any(
        f["executor_type_name"] == "single_threaded_executor"
        for _, n, f in events if n == "agnocast_construct_executor"), "construct_executor")
    timers = [f for _, n, f in events if n == "agnocast_timer_init"]
    check(len(timers) == 1 and timers[0]["period"] == 1_000_000 and
          nodes.get(timers[0]["node_handle"]) == "source" and
          timers[0]["callback_group"] in groups, f"timer_init: {timers}")

    publishers = {f["publisher_handle"]: f for _, n, f in events if n == "agnocast_publisher_init"}
    subscriptions = {f["subscription_handle"]: f
                     for _, n, f in events if n == "agnocast_subscription_init"}
    topic_of_publisher = {h: f["topic_name"] for h, f in publishers.items()}
    topic_of_subscription = {h: f["topic_name"] for h, f in subscriptions.items()}
    topics = sorted(set(topic_of_publisher.values()))
    if not check(len(topics) == 2 and topics[0].endswith("_a") and topics[1].endswith("_b") and
                 sorted(topic_of_subscription.values()) == topics,
                 f"publisher_init/subscription_init topics: {publishers} {subscriptions}"):
        return
    first, second = topics
    for handle, f in subscriptions.items():
        check(f["callback"] == handle and f["callback_group"] in groups and
              f["queue_depth"] == 10 and f["pid_ciid"] >> 32 == f["vpid"] and
              f["pid_ciid"] & 0xFFFFFFFF == f["subscriber_id"] and f["symbol"],
              f"subscription_init fields: {f}")
    for f in publishers.values():
        check(f["queue_depth"] == 10 and f["publisher_id"] > 0 and f["node_handle"] in nodes,
              f"publisher_init fields: {f}")

    # Each thread's sequence: take, create_callable, callable_start, then
    # (in the relay's callback) a publish, callable_end.
    publishes = {}  # (topic, entry) -> time
    takes = {}  # (topic, entry) -> time
    open_callable = {}  # vtid -> callable
    relayed = 0
    last_take = {}  # vtid -> (subscription, entry)
    timer_handle = timers[0]["timer_handle"]
    timer_calls = 0
    for time_, name, f in events:
        thread = f["vtid"]
        if name == "agnocast_publish":
            key = (topic_of_publisher.get(f["publisher_handle"]), f["entry_id"])
            check(f["topic_name"] == key[0] and
                  f["publisher_id"] == publishers[f["publisher_handle"]]["publisher_id"],
                  f"publish names another topic or publisher: {f}")
            check(key not in publishes, f"entry {key} published twice")
            publishes[key] = time_
            inside = open_callable.get(thread)
            if key[0] == first:
                check(inside == timer_handle, f"publish on {first} outside the timer's callback")
            elif key[0] == second:
                check(topic_of_subscription.get(inside) == first,
                      f"publish on {second} outside the relay's callback")
                relayed += 1
        elif name == "agnocast_take":
            key = (topic_of_subscription.get(f["subscription_handle"]), f["entry_id"])
            check(f["topic_name"] == key[0] and
                  f["subscriber_id"] == subscriptions[f["subscription_handle"]]["subscriber_id"],
                  f"take names another topic or subscriber: {f}")
            check(key in publishes, f"take of {key} before (or without) its publish")
            check(key not in takes, f"entry {key} taken twice")
            takes[key] = time_
            check(f["message"] != 0, "take without a message address")
            last_take[thread] = (f["subscription_handle"], f["entry_id"])
        elif name == "agnocast_create_callable":
            check(last_take.get(thread) == (f["callable"], f["entry_id"]),
                  f"create_callable {f} does not follow its take")
            check(f["pid_ciid"] == subscriptions[f["callable"]]["pid_ciid"], "pid_ciid differs")
        elif name == "agnocast_callable_start":
            check(thread not in open_callable, "callable_start inside a callable")
            open_callable[thread] = f["callable"]
            if f["callable"] == timer_handle:
                timer_calls += 1
            else:
                check(last_take.pop(thread, (None,))[0] == f["callable"],
                      f"a subscription's callable_start without its take: {f}")
        elif name == "agnocast_callable_end":
            check(open_callable.pop(thread, None) == f["callable"], f"callable_end unmatched: {f}")
    check(not open_callable, f"callables never ended: {open_callable}")
    for topic in topics:
        entries = sorted(entry for t, entry in publishes if t == topic)
        check(len(entries) == MESSAGES, f"{len(entries)} publishes on {topic}, not {MESSAGES}")
        check(sorted(entry for t, entry in takes if t == topic) == entries,
              f"on {topic} the takes are not the publishes")
    check(relayed == MESSAGES, f"{relayed} publishes inside the relay's callback")
    # Every message published was loaned first, on the thread that published it.
    loans = [f for _, n, f in events if n == "agnocast_loan"]
    check(len(loans) == 2 * MESSAGES and all(f["size"] == 8 and f["message"] for f in loans),
          f"{len(loans)} loans of 8 bytes, not {2 * MESSAGES}")
    check(timer_calls >= MESSAGES, f"{timer_calls} timer callbacks")
    check(by_name["agnocast_executor_wait"] > 0 and
          abs(by_name["agnocast_executor_wait"] - by_name["agnocast_executor_wake"]) <= 1,
          "executor_wait and executor_wake pair up")
    delays = sorted(takes[key] - publishes[key] for key in takes)
    print(f"publish -> take: median {delays[len(delays) // 2] * 1e6:.0f} us "
          f"over {len(delays)} entries")


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    heaphook_tests = sys.argv[2] if len(sys.argv) == 3 else None
    for tool in ("lttng", "lttng-sessiond", "babeltrace2"):
        if not shutil.which(tool):
            sys.exit(f"FAIL: {tool} is missing: scripts/install-deps testbed installs it")
    before = session_daemons()
    global context
    output = tempfile.mkdtemp(prefix="agnocast-lttng-")
    late_output = tempfile.mkdtemp(prefix="agnocast-lttng-late-")
    try:
        opted_out = record(sys.argv[1], heaphook_tests, output)
        events = read_trace(output)
        sent = sum(1 for _, _, f in events if f.get("vpid") == opted_out)
        check(sent == 0, f"the workload with AGNOCAST_LTTNG=0 sent {sent} events")
        events = [e for e in events if e[2].get("vpid") != opted_out]
        verify(events)
        if heaphook_tests:
            verify_heap_scopes(events)
        context = "session started late: "
        print("a session started after the workload made everything:")
        record_late(sys.argv[1], late_output)
        verify(read_trace(late_output))
    finally:
        shutil.rmtree(output, ignore_errors=True)
        shutil.rmtree(late_output, ignore_errors=True)
        for pid in session_daemons() - before:
            os.kill(pid, signal.SIGTERM)
        deadline = time.monotonic() + 10
        while session_daemons() - before and time.monotonic() < deadline:
            time.sleep(0.1)
    for failure in failures[:20]:
        print("FAIL:", failure)
    print("FAIL" if failures else "PASS")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
