#!/bin/sh
# SPDX-License-Identifier: ISC
# One clock in an MQTT stream: every message's utc is the run's clock (the
# clock the samples are logged on: sped up with -x, started at -t), events as
# well as states.  psensd runs at 600x from a time of day twelve hours from
# now, against a real mosquitto; a refused command's event must carry a utc
# within ten clock minutes (one real second) of the states around it, not
# the wall clock's, which is hours away.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in" && skip_all "psensd built without MQTT (WITH_MQTT=no)"
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[ -x "$MOSQ" ] || skip_all "mosquitto not installed"
command -v mosquitto_sub > /dev/null || skip_all "mosquitto-clients not installed"
example_results
P=$(free_port)
printf 'listener %s 127.0.0.1\nallow_anonymous true\nuser %s\n' "$P" "$(id -un)" > "$TMP/mosquitto.conf"
"$MOSQ" -c "$TMP/mosquitto.conf" 2> "$TMP/mosquitto.err" & track_pid $!
wait_for 5 mosquitto_pub -p "$P" -t probe -n
S="$TMP/sock"
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/psensd.db\nsocket = $S|" \
	config/psensd.conf > "$TMP/psensd.conf"
printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = lab\ncommands = all\n' "$P" >> "$TMP/psensd.conf"
mosquitto_sub -p "$P" -q 1 -v -t 'psensd/lab/+/state' -t 'psensd/lab/+/event' > "$TMP/sub.log" &
track_pid $!
# twelve hours from now on the local clock
start=$(date -d '+12 hours' +%H:%M)
"$BIN/psensd" -f "$TMP/psensd.conf" -t "$start" -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q "mqtt: connected" "$TMP/err"
wait_for 10 grep -q "/state " "$TMP/sub.log"
mosquitto_pub -p "$P" -q 1 -t psensd/lab/office/set/target -m nonsense
wait_for 10 grep -q command_refused "$TMP/sub.log"
# and a state after it
n=$(grep -c "/state " "$TMP/sub.log")
wait_for 10 sh -c "[ \$(grep -c '/state ' '$TMP/sub.log') -gt $((n + 1)) ]"
kill $PID; wait $PID
/usr/bin/python3 - "$TMP/sub.log" > "$TMP/gap" << 'EOP'
import datetime, json, sys, time
def t(s):
    return datetime.datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=datetime.timezone.utc).timestamp()
states, ev = [], None
for line in open(sys.argv[1]):
    topic, _, body = line.partition(" ")
    o = json.loads(body)
    if topic.endswith("/state"):
        states.append(t(o["utc"]))
    elif o.get("event") == "command_refused" and ev is None:
        ev = t(o["utc"])
gap = min(abs(ev - s) for s in states)
print("%.0f %.0f" % (gap, abs(ev - time.time())))
EOP
read gap wall < "$TMP/gap"
diag "refused command's utc: $gap s from the nearest state's, $wall s from the wall clock"
check "the event's utc is the run's clock: within 600 s of a state's ($gap s)" test "$gap" -le 600
done_testing
