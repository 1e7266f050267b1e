#!/bin/sh
# The module's trace events through tools nobody here wrote: perf and
# trace-cmd list all seven, and count and record exactly the publishes and
# receives of a talker and a listener (20 messages, each received once).
set -eu
. /opt/agnocast/bin/vm-test-lib.sh
tracing=/sys/kernel/tracing
[ -d "$tracing/events" ] || mount -t tracefs tracefs "$tracing"
events="publish receive release reclaim shed drop process_exit"

perf list 'agnocast:*' >perf-list.txt 2>&1
trace-cmd list -e '^agnocast:' >trace-cmd-list.txt 2>&1
for event in $events; do
  grep -q "agnocast:$event .*Tracepoint event" perf-list.txt ||
    { cat perf-list.txt; echo "perf list lacks agnocast:$event"; exit 1; }
  grep -qx "agnocast:$event" trace-cmd-list.txt ||
    { cat trace-cmd-list.txt; echo "trace-cmd list lacks agnocast:$event"; exit 1; }
done

# One talker and one listener, the listener subscribed before the first message.
cat >pair.sh <<PAIR
set -eu
. /opt/agnocast/bin/vm-test-lib.sh
topic=\$1
agnocast-listener --topic "\$topic" --count 20 --depth 20 --timeout 60 --json >"\$2" &
listener=\$!
wait_until 10 topic_queued "\$topic" || { echo "listener never subscribed"; exit 1; }
agnocast-talker --topic "\$topic" --count 20 --depth 20 --rate 0 --size 64
wait "\$listener"
PAIR
received='{"received":20,"corrupt":0,"first_seq":0,"last_seq":19,"missed":0,"max_size":64}'

# perf stat, system-wide: each event fires exactly once per message.
topic=/trace_tools/perf_$$
perf stat -a -x, -e agnocast:publish -e agnocast:receive -o perf-stat.csv sh pair.sh "$topic" perf.json
grep -qx "$received" perf.json || { cat perf.json; echo "the listener missed messages"; exit 1; }
cat perf-stat.csv
for event in publish receive; do
  count=$(grep ",agnocast:$event," perf-stat.csv | cut -d, -f1)
  [ "$count" = 20 ] || { echo "perf counted $count agnocast:$event, not 20"; exit 1; }
done

# trace-cmd record and report: every entry id once as published and once as
# received, on the topic that carried them.
topic=/trace_tools/trace_cmd_$$
timeout 120 trace-cmd record -q -e agnocast:publish -e agnocast:receive -o trace.dat \
  sh pair.sh "$topic" trace-cmd.json >/dev/null
grep -qx "$received" trace-cmd.json || { cat trace-cmd.json; echo "the listener missed messages"; exit 1; }
trace-cmd report -i trace.dat >report.txt 2>/dev/null
for event in publish receive; do
  grep -E " $event: +topic=$topic " report.txt | grep -o 'entry_id=[0-9]*' | sort -u >ids.txt
  lines=$(grep -cE " $event: +topic=$topic " report.txt || true)
  ids=$(wc -l <ids.txt)
  if [ "$lines" != 20 ] || [ "$ids" != 20 ] || ! grep -qx 'entry_id=0' ids.txt ||
     ! grep -qx 'entry_id=19' ids.txt; then
    grep " $event: " report.txt | head -n 5
    echo "trace-cmd report has $lines $event lines with $ids distinct entry ids, not 20 and 20 (0..19)"
    exit 1
  fi
done
echo "perf and trace-cmd ok"
