# Helpers the in-VM bridge tests source (busybox sh, as root, agnocast.ko
# loaded). DDS runs over the loopback interface with multicast turned on, so
# the bridge and the DDS peer (a separate process, as on another machine)
# discover each other as Cyclone DDS does on a real network.
set -u
. /opt/agnocast/bin/vm-test-lib.sh
status_file=/run/agnocast/bridge.json
bridge_pid=
helpers=

fail() {
	echo "FAIL: $*"
	for log in *.log; do
		[ -f "$log" ] && sed "s#^#  ${log%.log}| #" "$log" | tail -n 20
	done
	[ -f "$status_file" ] && echo "status: $(cat "$status_file")"
	[ -n "$bridge_pid" ] && kill -9 "$bridge_pid" 2>/dev/null
	for pid in $helpers; do kill -9 "$pid" 2>/dev/null; done
	exit 1
}

setup_dds_network() {
	ip link set lo up
	ip link set lo multicast on
	ip route add 224.0.0.0/4 dev lo 2>/dev/null
	# Room in the socket buffers for the fragments of multi-megabyte samples.
	echo 16777216 >/proc/sys/net/core/rmem_max
	echo 16777216 >/proc/sys/net/core/rmem_default
	echo 16777216 >/proc/sys/net/core/wmem_max
	CYCLONEDDS_URI='<General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General>'
	export CYCLONEDDS_URI
}

status_field() { grep -o "\"$1\":[a-z0-9]*" "$status_file" | head -n 1 | cut -d: -f2; }

# topic_counter TOPIC DIRECTION COUNTER: a counter of the status file.
topic_counter() {
	sed 's/},{/}\n{/g' "$status_file" | grep "\"name\":\"$1\"" | grep "\"direction\":\"$2\"" |
		grep -o "\"$3\":[0-9]*" | cut -d: -f2
}

bridge_running() {
	[ -f "$status_file" ] && [ "$(status_field pid)" = "$bridge_pid" ] &&
		[ "$(status_field running)" = true ]
}

# start_bridge CONFIG: starts agnocast-bridge and waits until it reports running.
start_bridge() {
	agnocast-bridge --config "$1" >>bridge.log 2>&1 &
	bridge_pid=$!
	wait_until 30 bridge_running || fail "agnocast-bridge did not start"
}

# stop_bridge: SIGTERM; it must exit 0 and say running:false.
stop_bridge() {
	kill -TERM "$bridge_pid"
	wait "$bridge_pid"
	rc=$?
	[ "$rc" -eq 0 ] || fail "agnocast-bridge exited $rc on SIGTERM"
	[ "$(status_field running)" = false ] || fail "status file still says running"
	bridge_pid=
}

# start_helper LOG COMMAND...: runs COMMAND in the background, its output in LOG.
start_helper() {
	log=$1; shift
	"$@" >"$log" 2>&1 &
	helper_pid=$!
	helpers="$helpers $helper_pid"
}

# wait_ready LOG: until the helper writing LOG printed @ready.
wait_ready() {
	wait_until 60 grep -q '^@ready' "$1" || fail "$1: never ready"
}

# expect_counter TOPIC DIRECTION COUNTER VALUE
expect_counter() {
	value=$(topic_counter "$1" "$2" "$3")
	[ "$value" = "$4" ] || fail "$1 $2 $3 is '$value', expected $4"
}
