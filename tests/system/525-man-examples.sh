#!/bin/sh
# SPDX-License-Identifier: ISC
# check: alone
# (the examples run against a psensd on a fast clock)
# Every EXAMPLE(S) line of every man page, run (tests/system/manex.py lists
# and classifies them): in a scratch directory holding the files the
# examples name (config/, sensor.sen, img/, test.wea, ofb.results), with the
# absolute paths of `make install` (default PREFIX /usr/local, /etc,
# /var/lib/psensd) under a DESTDIR staging tree the test installs, so a path
# that make install does not use fails.  psensctl lines talk to a psensd on
# the loopback room; psvirt's port is a free one and its serial line's ptys
# are in the test's directory; a server runs 3 s and is stopped; lines
# needing root are skipped with the reason, never passed.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] && [ -x "$BIN/psens" ] || skip_all "not built"
BINA=$(cd "$BIN" && pwd)
ROOT="$TMP/root"
make -s BUILD="$BUILD" install DESTDIR="$ROOT" > "$TMP/install.log" 2>&1 ||
	{ sed 's/^/# /' "$TMP/install.log"; skip_all "make install DESTDIR failed"; }
W="$TMP/w"; mkdir -p "$W/build"
cp -R config "$W/"
cp config/example/ofb/sensors/cosine.sen "$W/sensor.sen"
cp -R config/example/ofb/img "$W/img"
cp tests/data/gendaymtx/test.wea "$W/"
cp -R config/example/ofb/dc/sensor "$W/dc"   # psens(1)'s dc/dc_*.hdr
cp config/example/ofb/img/day_*_sensor_256.hdr "$W/"
mkdir -p "$W/tests/data" && cp -R tests/data/ofb-place "$W/tests/data/"   # psplace(1)'s poses and grid
"$BIN/psscene" -q -N -o "$W/ofb.results" "$W/config/example/ofb.scene"
cp "$W/ofb.results" "$W/build/ofb.results"   # config/psensd.conf's results (make run makes it)
PORT=$(free_port)
# the installed tree's paths, and the port
paths() {
	sed -e "s|/usr/local/|$ROOT/usr/local/|g; s|/etc/psensd|$ROOT/etc/psensd|g" \
	    -e "s|/var/lib/psensd|$ROOT/var/lib/psensd|g; s|/usr/share/|$ROOT/usr/share/|g" \
	    -e "s|1502|$PORT|g; s|/tmp/vdev|$TMP/vdev|g; s|/tmp/site|$TMP/site|g"
}

# psensctl's peer: psensd on the loopback room, zone office, at 3600x from 02:00
cat > "$TMP/ctl.conf" <<CONF
[psensd]
results = $W/ofb.results
database = $TMP/psensd.db
socket = $TMP/sock
period = 60
[device room]
driver = loopback
gain = 0.5
offset = 0.05
noise = 0.002
task_noise = 2
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point meter]
device = room
role = task
[zone office]
sensor = sensor
dim = lamp
task = meter
sensor_gain = 0.5
cal_window = 300
CONF
export PSENSD_SOCKET="$TMP/sock"
daemon=""
start_daemon() {
	[ -n "$daemon" ] && return 0
	"$BIN/psensd" -f "$TMP/ctl.conf" -t 02:00 -x 3600 > "$TMP/psensd.out" 2> "$TMP/psensd.err" &
	daemon=$!; track_pid $daemon
	wait_for 10 "$BIN/psensctl" ping > /dev/null
}

python3 tests/system/manex.py $(ls sim/cmd/*.[1-8] daemon/*/*.[1-8] drivers/*.[1-8] config/*.[1-8]) > "$TMP/list"
check "the man pages hold examples ($(grep -vc '^END' "$TMP/list") lines)" test "$(grep -vc '^END' "$TMP/list")" -gt 20
bg=""
tab=$(printf '\t')
while IFS="$tab" read -r kind page text; do
	name=$(basename "$page")
	case "$kind" in
	END)
		for p in $bg; do kill "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
		bg=""
		continue ;;
	SKIP:*)
		skip "$name: $text: ${kind#SKIP:}"
		continue ;;
	esac
	cmd=$(printf '%s\n' "$text" | paths)
	case "$cmd" in psensctl*|*" psensctl "*) start_daemon ;; esac
	case "$cmd" in mbpoll*) command -v mbpoll > /dev/null || { skip "$name: $text: mbpoll not installed"; continue; } ;; esac
	case "$kind" in
	RUN)
		# a session is accepted once it is done: wait for that, as the page's status shows
		case "$cmd" in
		*"calibrate office accept"*)
			wait_for 60 sh -c "'$BIN/psensctl' calibrate office status | grep -q 'state: done'" ;;
		*"calibrate office day"*)   # a day session by day: the clock runs an hour a second
			wait_for 60 sh -c "'$BIN/psensctl' status | awk '/^time:/ { split(\$2, t, \":\"); ok = t[1] >= 10 && t[1] < 15 } END { exit !ok }'" ;;
		esac
		(cd "$W" && PATH="$BINA:$PATH" sh -c "$cmd") > "$TMP/out" 2> "$TMP/err" < /dev/null; rc=$?
		check "$name: $text: exit $rc$( [ "$rc" = 0 ] || { printf ': '; tail -n 2 "$TMP/err" | tr '\n' ' '; })" test "$rc" = 0 ;;
	BG)
		(cd "$W" && PATH="$BINA:$PATH" exec sh -c "exec ${cmd%&}") > "$TMP/bg.out" 2> "$TMP/bg.err" < /dev/null &
		p=$!; track_pid $p; bg="$bg $p"
		sleep 1
		check "$name: $text: running in the background$(kill -0 $p 2>/dev/null || { printf ': '; tail -n 2 "$TMP/bg.err" | tr '\n' ' '; })" kill -0 $p ;;
	SERVER)
		(cd "$W" && PATH="$BINA:$PATH" exec sh -c "exec $cmd") > "$TMP/srv.out" 2> "$TMP/srv.err" < /dev/null &
		p=$!; track_pid $p
		case "$cmd" in psvirt*) wait_for 5 sh -c "grep -q 'zones on ' '$TMP/srv.out' '$TMP/srv.err'"; bg="$bg $p"
			check "$name: $text: serving$(kill -0 $p 2>/dev/null || { printf ': '; tail -n 2 "$TMP/srv.err" | tr '\n' ' '; })" kill -0 $p
			continue ;;
		esac
		sleep 3
		if kill -0 $p 2>/dev/null; then
			kill $p; wait $p 2>/dev/null
			ok "$name: $text: ran 3 s and stopped"
		else
			wait $p; not_ok "$name: $text: ended early (exit $?): $(tail -n 2 "$TMP/srv.err" | tr '\n' ' ')"
		fi ;;
	CONF)
		printf '%b\n' "$cmd" > "$TMP/example.conf"
		# its absolute paths are make install's: the installed files, or state in a directory it made
		for f in $(sed -n 's|^[a-z_]* *= *\(/[^ ;]*\).*|\1|p' "$TMP/example.conf" | grep "^$ROOT/"); do
			case "$f" in
			$ROOT/var/*) check "$name: $(echo "$f" | sed "s|$ROOT||") is in a directory make install makes" test -d "$(dirname "$f")" ;;
			*) check "$name: $(echo "$f" | sed "s|$ROOT||") is installed by make install" test -e "$f" ;;
			esac
		done
		if grep -q '^\[zone ' "$TMP/example.conf"; then
			(cd "$W" && "$BINA/psensd" -n -f "$TMP/example.conf") > "$TMP/out" 2> "$TMP/err"; rc=$?
			check "$name: its configuration example passes psensd -n (exit $rc$( [ "$rc" = 0 ] || { printf ': '; head -n 3 "$TMP/err" | tr '\n' ' '; }))" test "$rc" = 0
		else
			skip "$name: a configuration fragment (no [zone]): psensd -n cannot check it alone"
		fi ;;
	esac
done < "$TMP/list"
done_testing
