#!/bin/sh
# SPDX-License-Identifier: ISC
# Who may command the lights over MQTT: a real mosquitto with a password
# file (allow_anonymous false) and the ACL file psensd-mqtt(7) shows, taken
# from the man page itself.  A read-only dashboard user receives psensd's
# samples but its set/override has no effect (no reply, the level does not
# move), while an operator's does; with [mqtt] commands = override a
# set/target is refused with the scope named; with no commands key psensd
# does not subscribe at all (an operator's command goes unanswered), it
# removes its Home Assistant override entity, and it goes on publishing.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in" && skip_all "psensd built without MQTT (WITH_MQTT=no)"
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[ -x "$MOSQ" ] || skip_all "mosquitto not installed"
command -v mosquitto_passwd > /dev/null || skip_all "mosquitto_passwd not installed"
command -v mosquitto_sub > /dev/null || skip_all "mosquitto-clients not installed"
example_results
# the ACL of psensd-mqtt(7), for its site hq
MAN=$(find "$TOP/daemon" -name psensd-mqtt.7 | head -n 1)
check "psensd-mqtt(7) is there ($MAN)" test -n "$MAN"
sed -n '/^\.SH ACCESS CONTROL/,/^\.SH NOTES/p' "$MAN" | sed -n '/^\.nf/,/^\.fi/p' |
	sed '/^\.nf/d; /^\.fi/d' > "$TMP/acl"
check "the man page's ACL gives psensd, dashboard and operator users" \
	sh -c "grep -q '^user psensd$' '$TMP/acl' && grep -q '^user dashboard$' '$TMP/acl' && grep -q '^user operator$' '$TMP/acl'"
mosquitto_passwd -b -c "$TMP/passwd" psensd ps-secret 2> /dev/null
mosquitto_passwd -b "$TMP/passwd" dashboard dash-secret 2> /dev/null
mosquitto_passwd -b "$TMP/passwd" operator op-secret 2> /dev/null
chmod 600 "$TMP/passwd"
P=$(free_port)
cat > "$TMP/mosquitto.conf" << EOC
listener $P 127.0.0.1
allow_anonymous false
password_file $TMP/passwd
acl_file $TMP/acl
user $(id -un)
log_dest file $TMP/mosquitto.log
log_type all
EOC
"$MOSQ" -c "$TMP/mosquitto.conf" 2> "$TMP/mosquitto.err" & track_pid $!
as() { u=$1; pw=$2; shift 2; "$@" -p "$P" -u "$u" -P "$pw"; }
wait_for 5 as dashboard dash-secret mosquitto_sub -t psensd/hq/status -W 1 -C 1 -E
check "mosquitto refuses an anonymous client" sh -c "! mosquitto_pub -p $P -t probe -n 2> /dev/null"

S="$TMP/sock"
conf() {   # conf [COMMANDS]: the example on site hq, commands = COMMANDS (none: no key)
	printf 'ps-secret\n' > "$TMP/secret"; chmod 600 "$TMP/secret"
	sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/psensd.db\nsocket = $S|; /^faults = /d" \
		config/psensd.conf > "$TMP/psensd.conf"
	printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = hq\nuser = psensd\npassword_file = secret\n' "$P" >> "$TMP/psensd.conf"
	[ -z "${1:-}" ] || printf 'commands = %s\n' "$1" >> "$TMP/psensd.conf"
}
level() { "$BIN/psensctl" -s "$S" -j status | grep -o '"level":[0-9.e-]*' | head -n 1 | cut -d: -f2; }
# a dashboard's view of everything
mosquitto_sub -q 1 -v -t 'psensd/#' -t 'homeassistant/#' -p "$P" -u dashboard -P dash-secret > "$TMP/dash.log" &   # not through as(): $! must be the client
track_pid $!
conf override
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q '^psensd/hq/office/state' "$TMP/dash.log"
check "psensd under the ACL: the dashboard receives its samples" grep -q '^psensd/hq/office/state {"id":' "$TMP/dash.log"
check "and its status (online)" grep -q '^psensd/hq/status online' "$TMP/dash.log"
check "psensd logs commands override" grep -q 'mqtt: .*commands override' "$TMP/err"

# the dashboard tries; then the operator: the operator's lands, the dashboard's never does
as dashboard dash-secret mosquitto_pub -q 1 -t psensd/hq/office/set/override -m '{"level": 0.15, "id": "dash"}'
as operator op-secret mosquitto_pub -q 1 -t psensd/hq/office/set/override -m '{"level": 0.25, "seconds": 6000, "id": "op"}'
wait_for 10 grep -q '"id":"op","reply":{"ok":true' "$TMP/dash.log"
check "the operator's set/override: reply ok" grep -q '"id":"op","reply":{"ok":true' "$TMP/dash.log"
check "and the level it set (0.25 = $(level))" test "$(level)" = 0.25
check "the dashboard's set/override: no reply" sh -c "! grep -q '\"id\":\"dash\"' '$TMP/dash.log'"
check "psensd never saw it (its log names only the operator's override)" \
	sh -c "[ \$(grep -c 'mqtt: set/override for zone office' '$TMP/err') = 1 ] && grep -q 'override office 0.25 ' '$TMP/err'"
check "mosquitto denied it" grep -q "Denied PUBLISH from .*psensd/hq/office/set/override" "$TMP/mosquitto.log"
# the operator, beyond commands = override
as operator op-secret mosquitto_pub -q 1 -t psensd/hq/office/set/target -m '{"lux": 123, "id": "tg"}'
wait_for 10 grep -q 'set/target is not allowed' "$TMP/dash.log"
check "set/target with commands = override: refused with the scope named" \
	grep -q '^psensd/hq/office/event {"event":"command_refused","command":"target",.*set/target is not allowed: \[mqtt\] commands = override' "$TMP/dash.log"
check "the target is unchanged" sh -c "! \"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"target_lux\":123'"
as operator op-secret mosquitto_pub -q 1 -t psensd/hq/office/set/release -n
wait_for 10 grep -q '"command":"release","id":null,"reply":{"ok":true' "$TMP/dash.log"
check "set/release (in the override scope): ok" grep -q '"command":"release","id":null,"reply":{"ok":true' "$TMP/dash.log"
check "Home Assistant's override entity is announced" \
	grep -q '^homeassistant/number/psensd_hq_office/override/config {' "$TMP/dash.log"
kill $PID; wait $PID; rc=$?
check "psensd exits 0 on SIGTERM" test "$rc" = 0

# no commands key: not subscribed; the override entity is removed; samples still go out
conf
mosquitto_sub -q 1 -v -t 'psensd/#' -t 'homeassistant/#' -p "$P" -u dashboard -P dash-secret > "$TMP/dash2.log" &   # not through as(): $! must be the client
track_pid $!
wait_for 10 grep -q '^psensd/hq/status offline' "$TMP/dash2.log"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/err2" &
PID=$!; track_pid $PID
wait_for 10 grep -q '^psensd/hq/office/state' "$TMP/dash2.log"
check "by default: commands none, logged" grep -q 'mqtt: .*commands none (not subscribed)' "$TMP/err2"
check "samples are published" grep -q '^psensd/hq/office/state {"id":' "$TMP/dash2.log"
before=$(level)
as operator op-secret mosquitto_pub -q 1 -t psensd/hq/office/set/override -m '{"level": 0.35, "seconds": 6000, "id": "op2"}'
# a full second of psensd's turns: a subscribed psensd answers in milliseconds (above)
sleep 1
check "an operator's set/override: no reply" sh -c "! grep -q '\"id\":\"op2\"' '$TMP/dash2.log'"
check "and no effect (level $before, then $(level))" test "$(level)" != 0.35
check "not in psensd's log" sh -c "! grep -q 'set/override' '$TMP/err2'"
# the last config message of the entity: empty (mosquitto_sub -v shows "(null)" or nothing)
ovr() { grep -a '^homeassistant/number/psensd_hq_office/override/config' "$TMP/dash2.log" | tail -n 1 | grep -q 'config \(\|(null)\)$'; }
wait_for 5 ovr
check "the override entity is removed (an empty retained config)" ovr
kill $PID; wait $PID; rc=$?
check "psensd exits 0 on SIGTERM" test "$rc" = 0
done_testing
