#!/bin/sh
# seed::Msg, a type with std::vector/std::string members, published with the
# allocation hook (preloaded, or linked) to a subscriber without it; and
# refused, saying how to enable the hook, without it.
set -eu
hook=/opt/agnocast/bin/libagnocast_heaphook.so
secret="private-$$-"

# TOPIC COUNT THREADS MODE PUBLISHER...: one subscriber, one publisher process.
exchange() {
  topic=$1 count=$2 threads=$3 mode=$4
  shift 4
  heap_subscriber "$topic" $((count * threads)) "$secret" >sub.out 2>sub.err &
  subscriber=$!
  if ! "$@" "$topic" "$count" "$threads" "$mode" "$secret" >pub.out 2>pub.err; then
    echo "publisher failed ($*):"; cat pub.err; kill "$subscriber" 2>/dev/null; exit 1
  fi
  if ! wait "$subscriber"; then
    echo "subscriber failed ($*):"; cat sub.err; exit 1
  fi
  cat pub.out sub.out
}

exchange /heap/preloaded_threads 40 3 threads env LD_PRELOAD=$hook heap_publisher
exchange /heap/preloaded_executor 20 2 executor env LD_PRELOAD=$hook heap_publisher
exchange /heap/linked 30 1 threads heap_publisher_linked

if heap_publisher /heap/no_hook 1 1 threads "$secret" >pub.out 2>pub.err; then
  echo "published a heap message without the hook"; exit 1
fi
cat pub.err
grep -q 'seed/msg/Msg keeps std::vector/std::string members' pub.err
grep -q 'LD_PRELOAD=libagnocast_heaphook.so' pub.err
grep -q 'agnocast::heaphook' pub.err
echo "heap messages ok"
