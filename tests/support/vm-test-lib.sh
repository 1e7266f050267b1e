# Helpers every in-VM shell test may source (busybox sh):
#   . /opt/agnocast/bin/vm-test-lib.sh

# Hundredths of a second since boot.
now_cs() { sed 's/^\([0-9]*\)\.\([0-9]*\) .*/\1\2/' /proc/uptime; }

# wait_until SECONDS COMMAND...: polls COMMAND every 50 ms; false after
# SECONDS. On success waited_ms says how long it took.
wait_until() {
	limit_cs=$(($1 * 100)); shift
	start_cs=$(now_cs)
	while ! "$@"; do
		[ $(($(now_cs) - start_cs)) -ge "$limit_cs" ] && return 1
		sleep 0.05
	done
	waited_ms=$((($(now_cs) - start_cs) * 10))
	return 0
}

# topic_queued TOPIC: a subscriber's notification queue for TOPIC exists
# (/a/b's are /dev/mqueue/a_b@<id>), i.e. someone subscribed to it.
topic_queued() {
	ls /dev/mqueue | grep -q "^$(echo "$1" | cut -c2- | tr / _)@"
}
