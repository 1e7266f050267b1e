#!/bin/sh
# agnocast-talker -> agnocast-listener across two processes, --json summary exact.
set -eu
topic=/examples/chatter_$$
# Depth 20 on both sides: a listener slower than the talker still loses none.
agnocast-listener --topic "$topic" --count 20 --depth 20 --timeout 60 --json >listener.json &
listener=$!
# The listener's queue exists once it subscribed.
mangled=$(echo "$topic" | cut -c2- | tr / _)
tries=0
until ls /dev/mqueue | grep -q "^$mangled@"; do
  tries=$((tries + 1))
  [ "$tries" -lt 200 ] || { echo "listener never subscribed"; exit 1; }
  sleep 0.05
done
agnocast-talker --topic "$topic" --count 20 --depth 20 --rate 0 --size 100000
wait "$listener"
cat listener.json
grep -qx '{"received":20,"corrupt":0,"first_seq":0,"last_seq":19,"missed":0,"max_size":100000}' listener.json
# --count stops at exactly that many, even when wake-ups deliver batches.
wait_subscribed() {
  tries=0
  until ls /dev/mqueue | grep -q "^$1@"; do
    tries=$((tries + 1))
    [ "$tries" -lt 200 ] || { echo "listener never subscribed"; exit 1; }
    sleep 0.05
  done
}
agnocast-listener --topic "${topic}_batch" --count 5 --depth 200 --timeout 60 --json >batch.json &
listener=$!
wait_subscribed "${mangled}_batch"
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
