"""Receives point clouds in Python and reads them in place: the numpy array is
a read-only view of the publisher's memory, valid as long as it is referenced."""
import sys

import numpy as np

import agnocast
from agnocast.msg.sensor_msgs import PointCloud2


def main(count):
    node = agnocast.Node("py_listener")
    executor = agnocast.SingleThreadedExecutor()
    received = []

    def on_cloud(msg, info):
        points = np.asarray(msg.data).view(np.float32).reshape(-1, 3)
        print(f"cloud from {msg.header.frame_id}: {len(points)} points, "
              f"centroid {points.mean(axis=0).round(2)}, {info.bytes} bytes", flush=True)
        received.append(msg)  # keeping a message keeps its memory valid
        if len(received) == count:
            executor.cancel()

    node.create_subscription(PointCloud2, "/points", agnocast.QoS(10), on_cloud)
    executor.add_node(node)
    executor.spin()  # until cancel(), or Ctrl-C (KeyboardInterrupt)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10)
