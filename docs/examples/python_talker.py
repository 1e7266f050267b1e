"""Publishes point clouds from Python: each message is borrowed from the
shared pool and filled in place through numpy, then handed over without a copy."""
import sys

import numpy as np

import agnocast
from agnocast.msg.sensor_msgs import PointCloud2, PointField


def main(count):
    node = agnocast.Node("py_talker")
    pub = node.create_publisher(PointCloud2, "/points", agnocast.QoS(10))
    pub.wait_for_subscribers(1, 30.0)  # seconds; publishing without any is fine too
    for seq in range(count):
        msg = pub.borrow_loaned_message()
        msg.header.frame_id = "lidar"
        msg.height, msg.width, msg.point_step = 1, 1000, 12
        msg.fields.resize(3)
        for i, name in enumerate("xyz"):
            msg.fields[i].name = name
            msg.fields[i].offset = 4 * i
            msg.fields[i].datatype = PointField.FLOAT32
            msg.fields[i].count = 1
        msg.data.resize(1000 * 12)
        points = np.asarray(msg.data).view(np.float32).reshape(1000, 3)  # the pool memory
        points[:] = np.random.default_rng(seq).normal(size=(1000, 3))
        pub.publish(msg)  # msg is unusable from here on
        print(f"published cloud {seq}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10)
