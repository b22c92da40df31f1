#!/bin/sh
# SPDX-License-Identifier: ISC
# Three psensd instances (sites s1, s2, s3) publish to one mosquitto started
# here on a random 127.0.0.1 port with its own config file; a subscriber
# (mosquitto_sub, QoS 1, a persistent session) records every state message.
# Mid-run the broker is stopped and restarted (the instances keep logging
# and catch up when it is back), and s2 is killed with SIGKILL in the middle
# of its catch-up and restarted on its log.  Then every sample in each instance's database must
# have arrived, the first arrivals in id order (duplicates allowed, told
# apart by id): tests/system/peers/mqttcheck.py.  Also: the Last Will
# (offline) of the killed instance, online again after its restart.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in" && skip_all "psensd built without MQTT (WITH_MQTT=no)"
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[ -x "$MOSQ" ] || skip_all "mosquitto not installed"
command -v mosquitto_sub > /dev/null || skip_all "mosquitto-clients not installed"
PEERS="$TOP/tests/system/peers"
example_results
P=$(free_port)
mkdir -p "$TMP/mq"
cat > "$TMP/mosquitto.conf" << EOC
listener $P 127.0.0.1
allow_anonymous true
persistence true
persistence_location $TMP/mq/
max_queued_messages 0
user $(id -un)
log_dest file $TMP/mosquitto.log
EOC
broker() { "$MOSQ" -c "$TMP/mosquitto.conf" 2>> "$TMP/mosquitto.err" & BROKER=$!; track_pid $BROKER; wait_for 5 mosquitto_pub -p "$P" -t probe -n; }
broker
check "mosquitto listens on 127.0.0.1:$P" mosquitto_pub -p "$P" -t probe -n

mosquitto_sub -p "$P" -q 1 -c -i fleet-sub -v -t 'psensd/+/+/state' -t 'psensd/+/status' > "$TMP/sub.log" 2> "$TMP/sub.err" &
SUB=$!; track_pid $SUB
# subscribed before any psensd publishes
wait_for 10 sh -c "mosquitto_pub -p $P -q 1 -t psensd/probe/status -m x && grep -q '^psensd/probe/status' '$TMP/sub.log'"

for s in s1 s2 s3; do
	mkdir -p "$TMP/$s"
	sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/$s/psensd.db\nsocket = $TMP/$s/sock|; /^faults = /d; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
		config/psensd.conf > "$TMP/$s/psensd.conf"
	printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = %s\nkeepalive = 5\nrate = 500\n' "$P" "$s" >> "$TMP/$s/psensd.conf"
done
# s2 catches up slowly (20 messages/s against 10 samples/s logged): its SIGKILL
# comes in the middle of a catch-up, with messages in flight
sed -i 's/^rate = 500$/rate = 20/' "$TMP/s2/psensd.conf"
start() {
	"$BIN/psensd" -f "$TMP/$1/psensd.conf" -t 08:00 -x 600 >> "$TMP/$1/out" 2>> "$TMP/$1/err" &
	eval "PID_$1=\$!"; track_pid $!
}
for s in s1 s2 s3; do start $s; done
count() { grep -c "^psensd/$1/" "$TMP/sub.log"; }
# each instance starts on its own (a sanitizer build takes a second or so):
# wait for all three, not only the last started
wait_for 20 sh -c "[ \$(grep -c '^psensd/s3/office/state' '$TMP/sub.log') -ge 10 ] && [ \$(grep -c '^psensd/s1/' '$TMP/sub.log') -gt 5 ] && [ \$(grep -c '^psensd/s2/' '$TMP/sub.log') -gt 5 ]"
check "all three sites publish (s1 $(count s1), s2 $(count s2), s3 $(count s3) messages)" \
	sh -c "[ $(count s1) -gt 5 ] && [ $(count s2) -gt 5 ] && [ $(count s3) -gt 5 ]"

# the broker goes away for 3 s: the instances keep controlling and logging
kill $BROKER; wait $BROKER 2>/dev/null
before=$(grep -c 'psensd/s1/office/state' "$TMP/sub.log")
sleep 3
grep -q "connection lost" "$TMP/s1/err"
check "s1 saw the connection go" grep -q "mqtt: connection lost" "$TMP/s1/err"
broker
check "the broker is back on the same port" mosquitto_pub -p "$P" -t probe -n
wait_for 15 grep -q "connected; publishing from sample" "$TMP/s1/err"
# s2 is killed while it publishes, then restarted on its log
wait_for 15 sh -c "[ \$(grep -c 'connected; publishing from sample' '$TMP/s2/err') -ge 2 ]"
sleep 0.5
kill -9 "$PID_s2"; wait "$PID_s2" 2>/dev/null
wait_for 10 sh -c "grep -q '^psensd/s2/status offline' '$TMP/sub.log'"
check "the Last Will: psensd/s2/status offline after SIGKILL" grep -q '^psensd/s2/status offline' "$TMP/sub.log"
# what s2's first run had logged (committed) when it died: its backlog
m0=$(sqlite3 "$TMP/s2/psensd.db" "SELECT max(rowid) FROM samples")
start s2
# s2 has caught up when its cursor (acknowledged by the broker) passed that
# backlog.  Not "within N samples of the log's last": the log commits in
# batches and the window holds messages in flight, so that gap is timing.
caught_up() {
	c=$("$BIN/psensctl" -s "$TMP/s2/sock" -j status 2>/dev/null | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["mqtt"]["cursor"])' 2>/dev/null)
	[ -n "$c" ] && [ "$c" -ge "$m0" ]
}
wait_for 30 caught_up
caught_up; diag "s2: cursor $c, backlog of the killed run up to sample $m0"
check "s2 caught up after its restart (its cursor passed the killed run's last sample)" caught_up
check "s2 back online" sh -c "tail -n 1000 '$TMP/sub.log' | grep -q '^psensd/s2/status online'"
for s in s1 s2 s3; do eval "kill \$PID_$s"; done
for s in s1 s2 s3; do eval "wait \$PID_$s" 2>/dev/null; done
# a clean stop does not wait for a backlog: what the broker has not
# acknowledged stays after the cursor and goes at the next start.  So
# each instance is started once more, until its cursor passes what the
# first run logged, and stopped again.
for s in s1 s2 s3; do
	eval "last_$s=\$(sqlite3 '$TMP/$s/psensd.db' 'SELECT max(rowid) FROM samples')"
	eval "cur_$s=\$(sqlite3 '$TMP/$s/psensd.db' \"SELECT sample FROM mqtt_cursor WHERE site = '$s'\")"
	eval "diag \"$s: stopped with its cursor at \$cur_$s of \$last_$s samples\""
done
/usr/bin/python3 "$PEERS/mqttcheck.py" "$TMP/sub.log" s1="$TMP/s1/psensd.db" s2="$TMP/s2/psensd.db" s3="$TMP/s3/psensd.db" > "$TMP/check0.out"
rc=$?
while read -r l; do diag "$l"; done < "$TMP/check0.out"
check "nothing up to the cursors is missing after the stop" test $rc = 0
for s in s1 s2 s3; do start $s; done
past() { c=$(sqlite3 "$TMP/$1/psensd.db" "SELECT sample FROM mqtt_cursor WHERE site = '$1'"); eval "[ \"\$c\" -ge \$last_$1 ]"; }
for s in s1 s2 s3; do wait_for 30 past $s; done
for s in s1 s2 s3; do eval "kill \$PID_$s"; done
for s in s1 s2 s3; do eval "wait \$PID_$s" 2>/dev/null; done
check "s1 resumed after the broker's return (received $before before, $(grep -c 'psensd/s1/office/state' "$TMP/sub.log") now)" \
	test "$(grep -c 'psensd/s1/office/state' "$TMP/sub.log")" -gt "$before"
# everything the logs hold has arrived (the subscriber may still be draining)
W="s1=$TMP/s1/psensd.db:$last_s1 s2=$TMP/s2/psensd.db:$last_s2 s3=$TMP/s3/psensd.db:$last_s3"
wait_for 20 /usr/bin/python3 "$PEERS/mqttcheck.py" --no-pending "$TMP/sub.log" $W > /dev/null
/usr/bin/python3 "$PEERS/mqttcheck.py" --no-pending "$TMP/sub.log" $W > "$TMP/check.out"
rc=$?
while read -r l; do diag "$l"; done < "$TMP/check.out"
check "every sample the first run logged, of s1, s2, s3, arrived, first arrivals in order" test "$rc" = 0
check "offline on a clean stop (retained)" sh -c "[ \"\$(mosquitto_sub -p $P -t psensd/s1/status -C 1 -W 3)\" = offline ]"
for s in s1 s2 s3; do
	c=$(sqlite3 "$TMP/$s/psensd.db" "SELECT sample FROM mqtt_cursor WHERE site = '$s'")
	eval "m=\$last_$s"
	check "$s: the persisted cursor ($c) passed the first run's last sample ($m)" test "$c" -ge "$m"
done
kill $SUB
done_testing
