#!/bin/sh
# agnocast-talker -> agnocast-listener across two processes, --json summary exact.
set -eu
. /opt/agnocast/bin/vm-test-lib.sh
topic=/examples/chatter_$$
# Depth 20 on both sides: a listener slower than the talker still loses none.
agnocast-listener --topic "$topic" --count 20 --depth 20 --timeout 60 --json >listener.json &
listener=$!
# The listener's queue exists once it subscribed.
wait_subscribed() {
  wait_until 10 topic_queued "$1" || { echo "listener never subscribed"; exit 1; }
}
wait_subscribed "$topic"
agnocast-talker --topic "$topic" --count 20 --depth 20 --rate 0 --size 100000
wait "$listener"
cat listener.json
grep -qx '{"received":20,"corrupt":0,"first_seq":0,"last_seq":19,"missed":0,"max_size":100000}' listener.json
# --count stops at exactly that many, even when wake-ups deliver batches.
agnocast-listener --topic "${topic}_batch" --count 5 --depth 200 --timeout 60 --json >batch.json &
listener=$!
wait_subscribed "${topic}_batch"
agnocast-talker --topic "${topic}_batch" --count 200 --depth 200 --rate 0 --size 64
wait "$listener"
cat batch.json
grep -qx '{"received":5,"corrupt":0,"first_seq":0,"last_seq":4,"missed":0,"max_size":64}' batch.json
# A timeout exits 1 with the summary still printed.
if agnocast-listener --topic "$topic" --count 1 --timeout 1 --json >timeout.json; then
  echo "listener should fail on timeout"; exit 1
fi
grep -q '"received":0' timeout.json
echo "examples ok"
