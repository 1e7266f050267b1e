"""agnocast-bench's Python subscriber: one-way latency from a C++ publisher
to a Python callback (the series python_subscriber_constant_bytes).

usage: python3 python_subscriber.py TOPIC COUNT SIZE ACK_FD
Subscribes sensor_msgs/PointCloud2 on TOPIC; for each message, takes the
time first, then checks the message in place (its size, its sequence number
and its last byte, read through the numpy view of the publisher's memory),
writes one byte to ACK_FD and, after COUNT messages, prints each latency
(ns, publish to callback; -1 for a message that arrived wrong) on one line."""
import os
import sys
import time

import numpy as np

import agnocast
from agnocast.msg.sensor_msgs import PointCloud2


def main(topic, count, size, ack_fd):
    node = agnocast.Node("bench_python_subscriber")
    executor = agnocast.SingleThreadedExecutor()
    latencies = []

    def on_cloud(msg, info):
        received = time.monotonic_ns()  # the clock of the publisher's stamp
        data = np.asarray(msg.data)
        intact = (data.size == size and msg.header.stamp.sec == len(latencies)
                  and int(data[-1]) == msg.header.stamp.nanosec)
        latencies.append(received - info.publish_time if intact else -1)
        os.write(ack_fd, b"\x01")
        if len(latencies) == count:
            executor.cancel()

    node.create_subscription(PointCloud2, topic, agnocast.QoS(10), on_cloud)
    executor.add_node(node)
    executor.spin()
    print(" ".join(map(str, latencies)), flush=True)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]))
