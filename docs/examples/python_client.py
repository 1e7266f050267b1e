"""Calls example_interfaces/srv/AddTwoInts from Python: the request is built in
this process's shared pool and read in place by the server; the response is
read in place in the server's pool."""
import sys

import agnocast
from agnocast.srv.example_interfaces import AddTwoInts


def main(count):
    node = agnocast.Node("py_add_client")
    client = node.create_client(AddTwoInts, "/add_two_ints")
    if not client.wait_for_service(timeout_sec=30.0):
        sys.exit("no server for /add_two_ints")
    for i in range(count):
        request = client.borrow_loaned_request()
        request.a, request.b = i, 100
        response = client.call(request, timeout_sec=10.0)  # blocks; needs no executor
        print(f"{i} + 100 = {response.sum}", flush=True)

    # Without blocking: a concurrent.futures.Future, completed by the executor.
    future = client.call_async(AddTwoInts.Request(a=20, b=22))
    agnocast.spin_until_future_complete(node, future, timeout_sec=10.0)
    print(f"20 + 22 = {future.result().sum}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
