"""Python services against the kernel module, C++ servers and clients, and
agnocast-cli service call (run in the VM).

The C++ side is python_peer (python_peer.cpp), found on PATH with agnocast-cli."""
import json
import logging
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import agnocast
from agnocast.srv.example_interfaces import AddTwoInts
from agnocast.srv.std_srvs import Empty, SetBool, Trigger
from agnocast.srv.wheel_msgs import Rate


def peer(*args):
    return subprocess.Popen(["python_peer", *map(str, args)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)


def finish(process):
    """Closes the peer's stdin, which tells it to stop, and waits for it."""
    out, _ = process.communicate(timeout=60)
    assert process.returncode == 0, out
    return out.splitlines()


def pool_mapping_of(pid, address):
    """The /proc/<pid>/maps line whose range holds address."""
    with open(f"/proc/{pid}/maps") as maps:
        for line in maps:
            low, high = (int(x, 16) for x in line.split()[0].split("-"))
            if low <= address < high:
                return line.strip()
    return None


class Spinning:
    """Spins a node on a thread of its own while in the with-block."""

    def __init__(self, node):
        self.executor = agnocast.SingleThreadedExecutor()
        self.executor.add_node(node)
        self.thread = threading.Thread(target=self.executor.spin)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.executor.cancel()
        self.thread.join()


def test_messages_of_service_types_are_made_in_the_pool():
    request = AddTwoInts.Request(a=1, b=2)
    assert (request.a, request.b) == (1, 2)
    assert isinstance(request, AddTwoInts.Request) and isinstance(request, agnocast.Message)
    assert Trigger.Response().message == ""


def test_a_python_client_calls_a_cpp_server_zero_copy_both_ways():
    cpp = peer("serve", "add", "/py/svc/cpp_add")
    assert cpp.stdout.readline().strip() == "ready"
    node = agnocast.Node("py_client")
    client = node.create_client(AddTwoInts, "/py/svc/cpp_add")
    assert client.service_name == "/py/svc/cpp_add"
    assert client.wait_for_service(30.0)
    assert client.service_is_ready()
    request = client.borrow_loaned_request()
    request.a, request.b = 40, 2
    request_address = request._address
    response = client.call(request, 10.0)  # nobody spins the node: call() receives it
    assert response.sum == 42
    with pytest.raises(agnocast.MessagePublished):
        request.a
    with pytest.raises(agnocast.ReadOnlyMessage):
        response.sum = 1
    # This process reads the response in a read-only mapping of the server's pool.
    mapping = pool_mapping_of(os.getpid(), response._address)
    assert mapping is not None and mapping.split()[1].startswith("r-")
    # A constructed request works as well as a borrowed one.
    assert client.call(AddTwoInts.Request(a=-5, b=3), 10.0).sum == -2
    lines = finish(cpp)
    _, a, b, seen, written = lines[0].split()
    assert (a, b) == ("40", "2")
    # The server read the request where this process wrote it, and this
    # process reads the response where the server wrote it.
    assert int(seen, 16) == request_address
    assert int(written, 16) == response._address


def test_call_async_is_a_future_the_executor_completes():
    cpp = peer("serve", "add", "/py/svc/cpp_async")
    assert cpp.stdout.readline().strip() == "ready"
    node = agnocast.Node("py_async")
    client = node.create_client(AddTwoInts, "/py/svc/cpp_async")
    assert client.wait_for_service(30.0)
    futures = [client.call_async(AddTwoInts.Request(a=i, b=10)) for i in range(3)]
    seen = []
    futures[0].add_done_callback(lambda future: seen.append(future.result().sum))
    for future in futures:
        assert agnocast.spin_until_future_complete(node, future, timeout_sec=30.0)
    assert [future.result().sum for future in futures] == [10, 11, 12]
    assert seen == [10]
    finish(cpp)


def test_a_cpp_client_and_service_call_reach_a_python_server():
    node = agnocast.Node("py_server")
    requests = []

    def add(request, response):
        # The request, read in a read-only mapping of the client's pool.
        requests.append((request.a, request.b, pool_mapping_of(os.getpid(), request._address)))
        response.sum = request.a + request.b
        requests.append(response._address)

    def set_bool(request, response):
        response.success = request.data
        response.message = "switched on" if request.data else "switched off"

    add_server = node.create_service(AddTwoInts, "/py/svc/py_add", add)
    assert add_server.service_name == "/py/svc/py_add"
    node.create_service(SetBool, "/py/svc/py_set_bool", set_bool)
    with Spinning(node):
        lines = finish(peer("call", "add", "/py/svc/py_add", 40, 2))
        cli = subprocess.run(["agnocast-cli", "service", "call", "/py/svc/py_set_bool",
                              "std_srvs/srv/SetBool", '{"data": true}'],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             timeout=60)
        cli_json = subprocess.run(["agnocast-cli", "service", "call", "/py/svc/py_add",
                                   "example_interfaces/srv/AddTwoInts", '{"a": 1, "b": 2}',
                                   "--json"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  timeout=60)
    _, total, response_address = lines[0].split()
    assert total == "42"
    (a, b, mapping), written = requests[0], requests[1]
    assert (a, b) == (40, 2)
    assert mapping is not None and mapping.split()[1].startswith("r-")
    # The client read the response where this process wrote it.
    assert int(response_address, 16) == written
    assert cli.returncode == 0, cli.stderr
    assert cli.stdout == 'success: true\nmessage: "switched on"\n'
    assert cli_json.returncode == 0, cli_json.stderr
    assert json.loads(cli_json.stdout) == {"sum": 3}


def test_the_callback_may_return_the_response_as_rclpy_does():
    node = agnocast.Node("py_returning")

    def trigger(request, response):
        answer = Trigger.Response()
        answer.success, answer.message = True, "a response of its own"
        return answer

    node.create_service(Trigger, "/py/svc/returning", trigger)
    client = node.create_client(Trigger, "/py/svc/returning")
    with Spinning(node):
        response = client.call(Trigger.Request(), 10.0)
    assert response.success and response.message == "a response of its own"


def test_without_a_server_calls_fail_and_waits_time_out():
    node = agnocast.Node("py_alone")
    client = node.create_client(SetBool, "/py/svc/nobody")
    assert not client.service_is_ready()
    start = time.monotonic()
    assert not client.wait_for_service(0.2)
    assert time.monotonic() - start >= 0.2
    with pytest.raises(agnocast.ServiceUnavailable, match="has no server"):
        client.call(SetBool.Request(data=True), 5.0)
    future = client.call_async(SetBool.Request())
    assert future.done()
    assert isinstance(future.exception(), agnocast.ServiceUnavailable)
    assert issubclass(agnocast.ServiceUnavailable, agnocast.Error)


def test_an_unanswered_call_times_out_and_is_forgotten():
    server_node = agnocast.Node("py_slow_server")  # never spun: nothing is answered
    node = agnocast.Node("py_impatient")
    server_node.create_service(SetBool, "/py/svc/unanswered", lambda request, response: None)
    client = node.create_client(SetBool, "/py/svc/unanswered", qos=2)
    start = time.monotonic()
    with pytest.raises(TimeoutError):
        client.call(SetBool.Request(), 0.3)
    assert time.monotonic() - start >= 0.3
    assert client._pending() == 0
    # call_async: the bound of requests in flight, and forgetting them.
    first = client.call_async(SetBool.Request())
    second = client.call_async(SetBool.Request())
    with pytest.raises(agnocast.TooManyRequests):
        client.call_async(SetBool.Request())
    assert client.remove_pending_request(first)
    assert not client.remove_pending_request(first)
    assert second.cancel()
    assert client._pending() == 0
    assert client.prune_pending_requests() == 0


def test_a_second_server_and_another_type_are_refused():
    node = agnocast.Node("py_refusals")
    node.create_service(SetBool, "/py/svc/taken", lambda request, response: None)
    with pytest.raises(agnocast.ServiceExists, match=f"pid {os.getpid()}"):
        node.create_service(SetBool, "/py/svc/taken", lambda request, response: None)
    with pytest.raises(agnocast.TypeMismatch):
        node.create_client(Trigger, "/py/svc/taken")
    with pytest.raises(ValueError):
        node.create_client(SetBool, "no_slash")


def test_a_server_that_goes_away_fails_what_it_left_pending():
    server_node = agnocast.Node("py_leaving")
    node = agnocast.Node("py_left")
    server = server_node.create_service(SetBool, "/py/svc/leaving", lambda rq, rs: None)
    client = node.create_client(SetBool, "/py/svc/leaving")
    future = client.call_async(SetBool.Request())
    server_node.destroy_service(server)
    del server
    assert agnocast.spin_until_future_complete(node, future, timeout_sec=30.0)
    assert isinstance(future.exception(), agnocast.ServiceUnavailable)


def test_an_exception_in_a_server_callback_reaches_spin():
    node = agnocast.Node("py_failing_server")

    def fail(request, response):
        raise RuntimeError("from the service")

    node.create_service(Empty, "/py/svc/failing", fail)
    client = node.create_client(Empty, "/py/svc/failing")
    client.call_async(Empty.Request())
    with pytest.raises(RuntimeError, match="from the service"):
        agnocast.spin(node)


def test_requests_that_lie_cannot_crash_a_python_server(caplog):
    # python_peer hostile-client sends a request whose speeds point outside
    # its pool, one whose name does, then an honest one.
    node = agnocast.Node("py_hostile_server")
    refused = []

    def rate(request, response):
        speeds = np.asarray(request.speeds)  # raises InvalidMessage for a lying request
        response.mean = float(speeds.mean())
        response.verdict = request.name.split(",")[0]
        assert not speeds.flags.writeable

    node.create_service(Rate, "/py/svc/rate", rate)
    caplog.set_level(logging.WARNING, logger="agnocast")
    with Spinning(node):
        lines = finish(peer("hostile-client", "rate", "/py/svc/rate"))
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            refused = [r for r in caplog.records if "refused unanswered" in r.getMessage()]
            if len(refused) == 2:
                break
            time.sleep(0.05)
    assert lines == ["answered 2.5 front left"]
    assert len(refused) == 2, caplog.text
    assert "field 'speeds'" in refused[0].getMessage()
    assert "field 'name'" in refused[1].getMessage()


def test_the_guides_examples_run():
    server = subprocess.Popen([sys.executable, "python_service.py", "4"],
                              stdout=subprocess.PIPE, text=True)
    client = subprocess.run([sys.executable, "python_client.py", "3"], stdout=subprocess.PIPE,
                            text=True, timeout=120, check=True)
    assert client.stdout.splitlines() == [f"{i} + 100 = {i + 100}" for i in range(3)] + [
        "20 + 22 = 42"]
    out, _ = server.communicate(timeout=120)
    assert server.returncode == 0
    assert out.splitlines() == [f"{i} + 100 = {i + 100}" for i in range(3)] + ["20 + 22 = 42"]
