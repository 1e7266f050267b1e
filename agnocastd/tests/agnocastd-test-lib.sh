# Helpers the in-VM agnocastd tests source (busybox sh, as root, agnocast.ko
# loaded). Each test runs in its own working directory; the daemon's log is
# ./agnocastd.log there.
set -u
. /opt/agnocast/bin/vm-test-lib.sh
status_file=/run/agnocast/agnocastd.json
daemon_pid=

fail() {
	echo "FAIL: $*"
	[ -f agnocastd.log ] && sed 's/^/  agnocastd| /' agnocastd.log
	[ -n "$daemon_pid" ] && kill -9 "$daemon_pid" 2>/dev/null
	exit 1
}

# The value of a numeric or boolean field of the status file.
status_field() { grep -o "\"$1\":[a-z0-9]*" "$status_file" | cut -d: -f2; }

daemon_ready() {
	[ -f "$status_file" ] && [ "$(status_field pid)" = "$daemon_pid" ] &&
		[ "$(status_field running)" = true ]
}

# start_daemon [ARGS...]: starts agnocastd and waits until it reports running.
start_daemon() {
	agnocastd "$@" >>agnocastd.log 2>&1 &
	daemon_pid=$!
	wait_until 10 daemon_ready || fail "agnocastd did not become ready"
	echo "agnocastd $daemon_pid ready"
}

# stop_daemon: SIGTERM, then it must be gone within 2 s with exit status 0.
stop_daemon() {
	kill -TERM "$daemon_pid"
	wait_until 2 sh -c "! kill -0 $daemon_pid 2>/dev/null" ||
		fail "agnocastd did not stop within 2 s of SIGTERM"
	wait "$daemon_pid"
	rc=$?
	[ "$rc" -eq 0 ] || fail "agnocastd exited $rc after SIGTERM"
	echo "agnocastd stopped in ${waited_ms} ms"
	daemon_pid=
}

# The file names in /dev/mqueue of TOPIC's queues (mangled topic, no slash).
queues_of() { ls /dev/mqueue | grep "^$1@" || true; }

# ensure_module_loaded: the suite expects agnocast.ko loaded after each test.
ensure_module_loaded() {
	[ -e /dev/agnocast ] || insmod "$AGNOCAST_MODULE" || fail "cannot reload agnocast.ko"
}
