#!/bin/sh
# agnocast-msggen as a user runs it: output paths of a .msg and a .srv file,
# exit 1 with file:line on bad input, exit 2 on a usage error, nothing written
# on failure.
# usage: msggen_cli_test.sh MSGGEN SCRATCH_DIR
set -u
msggen=$1 scratch=$2
rm -rf "$scratch"
mkdir -p "$scratch/in/demo_msgs/msg" "$scratch/out"
fail() { echo "$*"; exit 1; }

printf 'int32 count\nstring<=4 name\n' >"$scratch/in/demo_msgs/msg/CountedName.msg"
"$msggen" --package demo_msgs --output-dir "$scratch/out" "$scratch/in/demo_msgs/msg/CountedName.msg" ||
  fail "valid input refused"
[ -f "$scratch/out/demo_msgs/msg/counted_name.hpp" ] || fail "no demo_msgs/msg/counted_name.hpp"

mkdir -p "$scratch/in/demo_msgs/srv"
printf 'int32 count\n---\nCountedName result\n' >"$scratch/in/demo_msgs/srv/GetCount.srv"
"$msggen" --package demo_msgs --output-dir "$scratch/out" \
  --include "demo_msgs=$scratch/in/demo_msgs/msg" "$scratch/in/demo_msgs/srv/GetCount.srv" ||
  fail "valid service refused"
[ -f "$scratch/out/demo_msgs/srv/get_count.hpp" ] || fail "no demo_msgs/srv/get_count.hpp"

printf 'int32 a\n---\nint32 b\n---\n' >"$scratch/in/demo_msgs/srv/Bad.srv"
"$msggen" --package demo_msgs --output-dir "$scratch/bad-out" "$scratch/in/demo_msgs/srv/Bad.srv" 2>"$scratch/err"
status=$?
[ "$status" -eq 1 ] || fail "bad service: exit $status, expected 1"
grep -qF "agnocast-msggen: $scratch/in/demo_msgs/srv/Bad.srv:4: a second '---'" "$scratch/err" ||
  fail "bad service: stderr lacks file:line: $(cat "$scratch/err")"
[ ! -e "$scratch/bad-out" ] || fail "bad service: something was written"

printf 'int32 a\nint32[<=0] b\n' >"$scratch/in/demo_msgs/msg/Bad.msg"
"$msggen" --package demo_msgs --output-dir "$scratch/bad-out" "$scratch/in/demo_msgs/msg/Bad.msg" 2>"$scratch/err"
status=$?
[ "$status" -eq 1 ] || fail "bad input: exit $status, expected 1"
grep -qF "agnocast-msggen: $scratch/in/demo_msgs/msg/Bad.msg:2: bad array bound '0'" "$scratch/err" ||
  fail "bad input: stderr lacks file:line: $(cat "$scratch/err")"
[ ! -e "$scratch/bad-out" ] || fail "bad input: something was written"

"$msggen" --output-dir "$scratch/out" "$scratch/in/demo_msgs/msg/CountedName.msg" 2>/dev/null
status=$?
[ "$status" -eq 2 ] || fail "missing --package: exit $status, expected 2"
"$msggen" --package demo_msgs --output-dir "$scratch/out" --include nodir \
  "$scratch/in/demo_msgs/msg/CountedName.msg" 2>/dev/null
status=$?
[ "$status" -eq 2 ] || fail "--include without '=': exit $status, expected 2"
echo "agnocast-msggen CLI ok"
