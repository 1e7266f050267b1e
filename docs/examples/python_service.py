"""Serves example_interfaces/srv/AddTwoInts from Python: each request is read
in place in the client's memory, each response is filled in this process's
shared pool and read in place by the client."""
import sys

import agnocast
from agnocast.srv.example_interfaces import AddTwoInts


def main(count):
    node = agnocast.Node("py_adder")
    executor = agnocast.SingleThreadedExecutor()
    answered = 0

    def add(request, response):
        nonlocal answered
        response.sum = request.a + request.b  # sent when the callback returns
        print(f"{request.a} + {request.b} = {response.sum}", flush=True)
        answered += 1
        if answered == count:
            executor.cancel()

    node.create_service(AddTwoInts, "/add_two_ints", add)
    executor.add_node(node)
    executor.spin()  # until cancel(), or Ctrl-C (KeyboardInterrupt)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10)
