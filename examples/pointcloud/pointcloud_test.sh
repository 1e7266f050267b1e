#!/bin/sh
# The PointCloud2 pipeline across three processes: driver -> filter -> consumer.
set -eu
. /opt/agnocast/bin/vm-test-lib.sh
raw=/examples/points_raw_$$
filtered=/examples/points_filtered_$$

# Waits until a subscriber's queue for topic $1 exists.
wait_for_subscriber() {
  wait_until 10 topic_queued "$1" || { echo "nobody subscribed to $1"; exit 1; }
}

agnocast-pointcloud-consumer --topic "$filtered" --count 10 --timeout 60 \
  --min-range 1.5 --max-range 6.5 >summary.json &
consumer=$!
wait_for_subscriber "$filtered"
agnocast-pointcloud-filter --input "$raw" --output "$filtered" --min-range 1.5 --max-range 6.5 &
filter=$!
wait_for_subscriber "$raw"
agnocast-pointcloud-driver --topic "$raw" --count 10 --rate 20 --points 1000
wait "$consumer"
kill "$filter"
wait "$filter" || true
cat summary.json
# Radii 2..6 of each ten (none near the band edges): half of the 1000 points of each scan.
grep -qx '{"scans":10,"points":5000,"out_of_range":0}' summary.json
echo "pointcloud pipeline ok"
