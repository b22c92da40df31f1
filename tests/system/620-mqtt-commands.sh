#!/bin/sh
# SPDX-License-Identifier: ISC
# MQTT commands against a real mosquitto ([mqtt] commands = all): set/override, set/target and the
# calibration verbs go through the control socket's own code (the error
# texts are compared with psensctl's for the same requests); malformed,
# oversized, wrongly typed, retained, unknown-zone and other-site commands
# are refused with an error event and psensd keeps running; a command
# retained while psensd is connected is refused too, not executed.  Then Home
# Assistant discovery: a zone renamed by SIGHUP has its retained config
# messages removed (empty) and the new one announced; a zone removed while
# psensd was stopped is removed at the next start (the announced list is
# kept in the database).  Fault events come from the log, with the sample ids.
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
conf() {   # conf ZONE: the example with its zone named ZONE
	sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/psensd.db\nsocket = $S|; s|^faults = .*|faults = open 08:00-08:30|; s|^\[zone office\]|[zone $1]|" \
		config/psensd.conf > "$TMP/psensd.conf"
	printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = lab\ncommands = all\n' "$P" >> "$TMP/psensd.conf"
}
conf office
last() { wait_for 5 grep -q -- "$1" "$TMP/sub.log"; grep -- "$1" "$TMP/sub.log" | tail -n 1; }
# got PATTERN TEXT: the last message matching PATTERN also holds TEXT
got() { last "$1" > "$TMP/last"; grep -q -- "$2" "$TMP/last"; }
# TCP sockets a process holds (/proc/PID/fd against /proc/net/tcp and tcp6)
tcp_socks() {
	/usr/bin/python3 - "$1" << 'EOP'
import os, sys
pid = sys.argv[1]
inodes = set()
for f in ("/proc/net/tcp", "/proc/net/tcp6"):
    for line in open(f).readlines()[1:]:
        inodes.add(line.split()[9])
n = 0
for fd in os.listdir("/proc/%s/fd" % pid):
    try:
        t = os.readlink("/proc/%s/fd/%s" % (pid, fd))
    except OSError:
        continue
    if t.startswith("socket:[") and t[8:-1] in inodes:
        n += 1
print(n)
EOP
}
# no [mqtt]: psensd opens no connection (and the same check sees the one it opens with [mqtt], below)
sed '/^\[mqtt\]/,$d' "$TMP/psensd.conf" > "$TMP/plain.conf"
"$BIN/psensd" -f "$TMP/plain.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/plain.err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
check "without [mqtt]: no TCP socket ($(tcp_socks $PID))" test "$(tcp_socks $PID)" = 0
check "and no MQTT message" sh -c "! grep -q mqtt '$TMP/plain.err'"
kill $PID; wait $PID

# a retained command, there before psensd subscribes: refused, not run at every connect
mosquitto_pub -p "$P" -q 1 -r -t psensd/lab/office/set/target -m 100
mosquitto_sub -p "$P" -q 1 -v -t 'psensd/lab/+/reply' -t 'psensd/lab/+/event' -t 'psensd/lab/event' > "$TMP/sub.log" &
track_pid $!
wait_for 10 sh -c "mosquitto_pub -p $P -q 1 -t psensd/lab/event -m probe && grep -q '^psensd/lab/event probe' '$TMP/sub.log'"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q "mqtt: connected" "$TMP/err"
check "psensd connected to the broker" grep -q "mqtt: connected" "$TMP/err"
check "with [mqtt]: one TCP socket, the broker's ($(tcp_socks $PID))" test "$(tcp_socks $PID)" = 1
check "a retained command: refused" got 'retained command' command_refused
mosquitto_pub -p "$P" -q 1 -r -t psensd/lab/office/set/target -n   # cleared
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
pub() { mosquitto_pub -p "$P" -q 1 "$@"; }

# a retained command published while psensd is connected: a 3.1.1 broker
# forwards it with the retain flag cleared; psensd must still refuse it
# (the same command, not retained, then sets the target: the refusal is the flag's)
n0=$(grep -c 'retained command' "$TMP/err")
pub -r -t psensd/lab/office/set/target -m '{"lux": 123, "id": "ret"}'
wait_for 5 sh -c "[ \$(grep -c 'retained command' '$TMP/err') -gt $n0 ]"
check "a retained set/target while connected: refused and logged" \
	sh -c "[ \$(grep -c 'mqtt: set/target for zone office refused: a retained command' '$TMP/err') -gt $n0 ]"
check "and not executed (target_lux is not 123)" sh -c "! \"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":123'"
check "no reply for it" sh -c "! grep -q '\"id\":\"ret\",\"reply\"' '$TMP/sub.log'"
pub -r -t psensd/lab/office/set/target -n   # cleared
pub -t psensd/lab/office/set/target -m '{"lux": 123, "id": "live"}'
wait_for 5 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":123'"
check "the same command not retained: executed (target_lux 123)" \
	sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":123'"

pub -t psensd/lab/office/set/override -m '{"level": 0.3, "seconds": 6000, "id": "r1"}'
check "set/override: reply ok with the request's id" got '"id":"r1"' '"reply":{"ok":true}'
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"level\":0.3'"
check "the override is in force (psensctl status: level 0.3)" sh -c "ctl() { \"$BIN/psensctl\" -s \"$S\" \"\$@\"; }; ctl -j status | grep -q '\"level\":0.3'"
pub -t psensd/lab/office/set/target -m 420
wait_for 5 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":420'"
check "set/target 420: the zone's target" sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":420'"
pub -t psensd/lab/office/set/release -n
wait_for 5 grep -q '"command":"release".*"ok":true' "$TMP/sub.log"
check "set/release (empty payload): ok" grep -q '"command":"release".*"ok":true' "$TMP/sub.log"

# the same validation code: the engine's words for an out-of-range request
sock_err=$(/usr/bin/python3 "$TOP/tests/system/peers/rawctl.py" "$S" send "override office 2 60" | sed 's/.*"error":"\([^"]*\)".*/\1/')
pub -t psensd/lab/office/set/override -m '{"level": 2, "seconds": 60, "id": "r2"}'
mq=$(last '"id":"r2"' | sed 's/.*"error":"\([^"]*\)".*/\1/')
check "level 2: refused with the socket's own error ('$sock_err' = '$mq')" test -n "$sock_err" -a "$sock_err" = "$mq"
pub -t psensd/lab/office/set/target -m 1e99 -q 1
check "target 1e99: refused by the engine's range check" got '"command":"target","id":null,"reply":{"ok":false' 'target'
pub -t psensd/lab/nowhere/set/target -m 300
check "an unknown zone: refused ('no zone')" got 'psensd/lab/nowhere/event' "no zone 'nowhere'"
pub -t psensd/lab/office/set/target -m '"abc"'
check "a string for a number: refused with an error event" got 'needs a number' command_refused
pub -t psensd/lab/office/set/target -m '{"lux": 300, "site": "other"}'
check "another site's command: refused" got "site 'other' refused" command_refused
pub -t psensd/lab/office/set/target -m "$(head -c 600 /dev/zero | tr '\0' 1)"
check "a 600-byte payload: refused" got 'at most 512' command_refused
pub -t psensd/lab/office/set/target -m '{"lux": 300' 
check "malformed JSON: refused" got 'not JSON' command_refused
pub -t psensd/lab/office/set/reboot -n
check "an unknown verb: refused" got 'no command set/reboot' command_refused
pub -t psensd/lab/office/set/calibrate -m '{"step": "dusk"}'
check "calibrate with an unknown step: refused" got "no step 'dusk'" command_refused
pub -t psensd/lab/office/set/accept -n
check "accept with no session: the calibration code's refusal" got 'reply {"command":"accept"' '"ok":false'
check "psensd still answers on its socket" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "and still runs" kill -0 $PID
"$BIN/psensctl" -s "$S" -j status > "$TMP/status"
check "psensctl status: the publisher is connected" grep -q '"mqtt":{"connected":true,' "$TMP/status"
check "psensctl status: the refusals are counted ($(grep -o '"refused":[0-9]*' "$TMP/status"))" \
	sh -c "[ \$(grep -o '\"refused\":[0-9]*' '$TMP/status' | cut -d: -f2) -ge 11 ]"

# the room's sensor is open from 08:00 to 08:30 (the first 3 s of a run at -x 600): a run's
# first sample is faulty, and its fault event comes all the same;
# a fault event with the first faulty sample's id, then fault_cleared, from the log
wait_for 30 grep -q '^psensd/lab/office/event {"event":"fault_cleared"' "$TMP/sub.log"
check "a fault event from the log ($(grep -o '"event":"fault","id":[0-9]*' "$TMP/sub.log" | head -n 1))" \
	grep -q '^psensd/lab/office/event {"event":"fault","id":[0-9]*,"utc":"[-0-9T:.]*Z","fault":"' "$TMP/sub.log"
id=$(grep -o '"event":"fault","id":[0-9]*' "$TMP/sub.log" | head -n 1 | cut -d: -f3)
check "its id is the first sample with the fault in the log ($id)" \
	test -n "$id" -a "$id" = "$(sqlite3 "$TMP/psensd.db" "SELECT min(rowid) FROM samples WHERE fault IS NOT NULL")"
check "fault_cleared when the sensor is back" grep -q '^psensd/lab/office/event {"event":"fault_cleared","id":[0-9]*' "$TMP/sub.log"

# Home Assistant discovery: the zone renamed by SIGHUP
ha() { mosquitto_sub -p "$P" -v -t 'homeassistant/#' -W 1 2>/dev/null | awk 'length($2) > 0 { print $1 }' | sort; }
# one entity per point the zone has (psensctl status' "points") and the override's number
NE=$("$BIN/psensctl" -s "$S" -j status | /usr/bin/python3 -c 'import json, sys; print(len(json.load(sys.stdin)["zones"][0]["points"]) + 1)')
wait_for 5 sh -c "mosquitto_sub -p $P -v -t 'homeassistant/#' -W 1 2>/dev/null | grep -q psensd_lab_office"
check "discovery: office's $NE entities are announced (retained)" test "$(ha | grep -c psensd_lab_office/)" = "$NE"
conf hall
kill -HUP $PID
wait_for 10 grep -q "zone office removed from Home Assistant" "$TMP/err"
check "SIGHUP: office leaves discovery" grep -q "zone office removed from Home Assistant" "$TMP/err"
sleep 0.5
check "no retained config of office is left" test "$(ha | grep -c psensd_lab_office/)" = 0
check "hall's entities are announced" test "$(ha | grep -c psensd_lab_hall/)" = "$NE"
check "a reload event" grep -q '^psensd/lab/event {"event":"reload"' "$TMP/sub.log"
kill $PID; wait $PID
conf lobby
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 >> "$TMP/out" 2>> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q "zone hall removed from Home Assistant" "$TMP/err"
sleep 0.5
check "at start: hall (announced before, now gone) is removed" test "$(ha | grep -c psensd_lab_hall/)" = 0
check "lobby announced" test "$(ha | grep -c psensd_lab_lobby/)" = "$NE"
kill $PID; wait $PID; rc=$?
check "psensd exits 0 on SIGTERM (no sanitizer report)" test "$rc" = 0
done_testing
