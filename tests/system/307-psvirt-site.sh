#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt for a whole site (psvirt(1), ZONES): one room per zone in one
# register map, configured from the command line (--zones, -o ZONE:KEY=VALUE)
# or from a psensd configuration (-f), and the shipped three-zone example
# (config/example/site.conf) dry-run end to end: the real psensd over Modbus
# TCP against one psvirt, both clocks at 3600x, checked from psensd's log
# against the scene's numbers zone by zone.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need mbpoll
need_pymodbus
make_results
S=$(summary electric_sensor_response); L=$(summary electric_task_lux)
py() { "$PY" "$PEERS/mbclient.py" tcp 127.0.0.1 "$port" "$@"; }
field() { echo "$1" | awk -v k="$2" '{ for (i = 1; i < NF; i++) if ($i == k) print $(i + 1) }'; }
counts() { awk -v g="$1" -v s="$S" 'BEGIN { printf "%d", g * s / 10 * 65535 + 0.5 }'; }

# ---- the map, from the command line: three zones from 02:00 in real time
# (night, full output, no noise), zone 1's sensor at 0.4 V per unit, zone
# 2's open circuit
port=$(free_port)
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
	--zones 3 --start 02:00 -D gain=0.5 -D lag_tau=0 -D 1:gain=0.4 \
	-D "2:faults=open 02:00-03:00" > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
pv=$!; track_pid $pv
check "psvirt --zones 3 ready" wait_for 10 test -s "$TMP/ready"
check "it names the zones and their registers: $(head -n 1 "$TMP/psvirt.out")" \
	grep -q "^psvirt: 3 zones on port $port, unit 1: 0 zone0 (AI0, AO0 at 10, lux at 100), 1 zone1 (AI1, AO1 at 11, lux at 110), 2 zone2" "$TMP/psvirt.out"
mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 0 -c 3 -t 3 127.0.0.1 > "$TMP/ai" 2>&1
ai0=$(sed -n 's/^\[0\]:[[:space:]]*//p' "$TMP/ai"); ai1=$(sed -n 's/^\[1\]:[[:space:]]*//p' "$TMP/ai")
ai2=$(sed -n 's/^\[2\]:[[:space:]]*//p' "$TMP/ai")
check "mbpoll: AI0 (input register 0) is 0.5 V/unit x the electric response: $ai0, want $(counts 0.5) +- 1" near "$ai0" "$(counts 0.5)" 1
check "AI1 is zone 1's own gain, 0.4 V/unit: $ai1, want $(counts 0.4) +- 1" near "$ai1" "$(counts 0.4)" 1
check "AI2 is zone 2's open circuit: $ai2" test "$ai2" = 0
got=$(py ir 20 3 | tr '\n' ' ')
check "status registers 20-22: only zone 2's open-circuit bit (8): $got" test "$got" = "0 0 8 "
for k in 0 1 2; do
	got=$(py u32 $((100 + 10 * k)))
	check "zone $k's task meter (u32 at $((100 + 10 * k))) is the electric task lux $L: $got" near "$got" "$L" 0.5
done
got=$(py write 11 2048)
check "pymodbus writes AO1 (holding register 11): $got" test "$got" = written
got="$(py hr 300 1) $(py hr 310 1) $(py hr 320 1) $(py hr 202 1)"
check "only zone 1's light output follows (300, 310, 320 and 202, zone 0's): $got" test "$got" = "10000 5001 10000 10000"
want=$(awk -v s="$S" 'BEGIN { printf "%d", 0.4 * s * 2048 / 4095 / 10 * 65535 + 0.5 }')
got=$(py ir 1 1)
check "and zone 1's sensor with it: AI1 $got, want $want +- 1" near "$got" "$want" 1
got=$(py f32 311)
check "zone 1's true task lux (f32 at 311) is half the electric: $got" near "$got" "$(awk -v l="$L" 'BEGIN { print l * 2048 / 4095 }')" 0.01
got=$(py write 13 77)
check "AO3 of an absent zone is plain memory: $got, reads $(py hr 13 1)" test "$got" = written -a "$(py hr 13 1)" = 77
kill "$pv"; wait "$pv"
check "psvirt exits 0" test $? = 0
check "and says what each zone used: $(tail -n 3 "$TMP/psvirt.out" | tr '\n' ' ')" \
	sh -c "grep -q '^psvirt: zone 1 zone1: light output' '$TMP/psvirt.out'"
# a zone's own drop and late faults touch that zone's registers only
port=$(free_port)
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready3" \
	--zones 3 --start 02:00 --late-ms 300 -D "1:faults=drop 02:00-03:00" -D "2:faults=late 02:00-03:00" \
	> /dev/null 2> "$TMP/psvirt3.err" &
pv=$!; track_pid $pv
check "psvirt with zone 1 dropping and zone 2 late ready" wait_for 10 test -s "$TMP/ready3"
got=$(py ir 0 1)
check "zone 0's AI0 answers ($got)" test -n "$got" -a "${got#e}" = "$got"
got=$(py ir 1 1)
check "zone 1's AI1 gets no reply ($got)" sh -c 'case "$1" in error*) exit 0;; esac; exit 1' sh "$got"
got=$(py hr 0 3)
check "a read of AI0-AI2 touches zone 1: no reply ($got)" sh -c 'case "$1" in error*) exit 0;; esac; exit 1' sh "$got"
got=$(py time 2 3)
check "zone 2's AI2 answers after the late delay, 300 ms: $got" \
	awk -v m="$(field "$got" median_ms)" -v e="$(field "$got" errors)" 'BEGIN { exit !(m >= 300 && e == 0) }'
got=$(py u32 200)
check "the time of day belongs to no zone and answers at once ($got s)" test "$got" -ge 7200 -a "$got" -lt 10800
kill "$pv"; wait "$pv"
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp 127.0.0.1:1 --zones 2 -D 2:gain=1 > /dev/null 2> "$TMP/e1"
check "an -o for a zone that does not exist: $(cat "$TMP/e1")" grep -q "no zone '2'" "$TMP/e1"
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp 127.0.0.1:1 --zones 11 > /dev/null 2> "$TMP/e2"
check "at most 10 zones: $(cat "$TMP/e2")" grep -q -- "--zones must be 1 to 10" "$TMP/e2"

# ---- the shipped example: config/example/site.conf, its paths and port
# pointed into $TMP, 15 simulated minutes a step
port=$(free_port)
sed -e "s|^results = .*|results = $TMP/ofb.results|" -e "s|^database = .*|database = $TMP/site.db|" \
	-e "s|^socket = .*|socket = $TMP/sock|" -e "s|^port = 1502|port = $port|" -e "s|^period = 60|period = 900|" \
	-e "s|^scene = .*|scene = $TMP/example/ofb.scene|" "$TOP/config/example/site.conf" > "$TMP/site.conf"
# as shipped: a copy of config/ with the build/ its paths name beside it
mkdir -p "$TMP/ship/build"
cp -R "$TOP/config" "$TMP/ship/config"
check "psensd -n accepts the example as shipped: $("$BIN/psensd" -f "$TMP/ship/config/example/site.conf" -n 2>&1)" \
	"$BIN/psensd" -f "$TMP/ship/config/example/site.conf" -n
# the options of the example's own dry-run line
# from 01:00: four and a half room hours (4.5 s) before sunrise, so that a
# sanitized psensd, whose start-up costs up to two room hours, still has
# samples of the night to judge
"$BIN/psvirt" -f "$TMP/site.conf" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready2" --start 01:00 --speed 3600 \
	-D gain=0.5 -D noise=0.002 -D task_noise=2 -D min_level=0.1 -D east:gain=0.4 \
	-D "south:faults=open 12:00-12:20" -D fade_rate=0 -D lag_tau=0 > "$TMP/site.out" 2> "$TMP/site.err" &
pv=$!; track_pid $pv
check "psvirt -f site.conf ready" wait_for 10 test -s "$TMP/ready2"
ready_ms=$(( $(date +%s%N) / 1000000 ))
check "its zones are the configuration's: $(head -n 1 "$TMP/site.out")" grep -q "0 north .*1 east .*2 south" "$TMP/site.out"
# psensd's clock starts where psvirt's is now (to the minute)
tod=$(py u32 200)
"$BIN/psensd" -f "$TMP/site.conf" -t "$(awk -v t="$tod" 'BEGIN { printf "%02d:%02d", t / 3600, t % 3600 / 60 }')" \
	-x 3600 > "$TMP/psensd.out" 2> "$TMP/psensd.err" &
pd=$!; track_pid $pd
# psensd's start-up leaves its clock behind psvirt's (a sanitizer build
# by most of an hour at 3600x): the night is judged on psvirt's clock
wait_for 20 "$BIN/psensctl" -s "$TMP/sock" ping > /dev/null
lag=$(clock_lag "$ready_ms" 3600 3600 "$TMP/sock")
diag "psvirt's clock $lag s of room time ahead of psensd's"
q() { sqlite3 "$TMP/site.db" "$1" 2>/dev/null; }
# to 16:00 room time (15 s)
wait_for 30 sh -c "[ \"\$(sqlite3 '$TMP/site.db' 'select max(tod_s) from samples' 2>/dev/null | cut -d. -f1)\" -ge 57600 ]"
kill -TERM $pd; wait $pd
kill "$pv"; wait "$pv"
diag "$(grep -e fault -e cleared "$TMP/psensd.err")"
diag "$(cat "$TMP/site.out")"
for z in north:500 east:400 south:500; do
	name=${z%:*}; target=${z#*:}
	want=$(awk -v t="$target" -v l="$L" 'BEGIN { print t / l }')
	night=$(q "select output from samples where zone = '$name' and tod_s < 19800 - $lag and fault is null order by t limit 1 offset 1")
	check "$name: before sunrise the level is $target lx / $L lx = $want ($night)" near "$night" "$want" 0.01
	noon=$(q "select max(output) from samples where zone = '$name' and tod_s >= 36000 - $lag and tod_s < 41400 - $lag and fault is null")
	check "$name: 10:00-11:30 the daylight is enough: the minimum level 0.1 (highest $noon)" near "$noon" 0.1 1e-6
	mean=$(q "select avg(abs(est_task_lux - task_lux) / task_lux) from samples where zone = '$name' and fault is null and task_lux > 100")
	check "$name: estimated against its meter: mean relative difference $mean (< 3 %)" awk -v m="$mean" 'BEGIN { exit !(m > 0 && m < 0.03) }'
done
check "south's open circuit at noon is a fault at the safe level" \
	test "$(q "select count(*) from samples where zone = 'south' and output = 1 and fault like '%outside%'")" -ge 1
check "and only south's: north and east have no fault" \
	test "$(q "select count(*) from samples where zone in ('north', 'east') and fault is not null")" = 0
check "south resumes by itself" grep -q "zone south: .* fault cleared: control resumes" "$TMP/psensd.err"
# site.conf marks the Modbus device as psvirt: psensd records each zone as
# simulated, and the record reads the sensor as virtual and says SIMULATED
check "psensd recorded the 3 zones as simulated by psvirt" \
	test "$(q "select count(*) from events where kind = 'simulated' and text like '%(psvirt)%'")" = 3
if command -v pdftotext > /dev/null; then
	"$BIN/psensctl" -d "$TMP/site.db" report -c config/example/site.conf -o "$TMP/site.pdf" > /dev/null 2>&1
	pdftotext -layout "$TMP/site.pdf" "$TMP/site.txt"
	pages=$(pdfinfo "$TMP/site.pdf" | awk '/^Pages:/ { print $2 }')
	check "every page of the site's record ($pages) says SIMULATED" \
		test "$(grep -c "SIMULATED . not a building's record" "$TMP/site.txt")" = "$pages"
	check "the sensors read as virtual rooms, not plain modbus" \
		sh -c "grep -q 'modbus, virtual: psvirt' '$TMP/site.txt' && ! grep -q 'sensor (modbus)' '$TMP/site.txt'"
	check "no sign-off block" sh -c "grep -q 'SIMULATED: no sign-off' '$TMP/site.txt' && ! grep -q Signature '$TMP/site.txt'"
	# north and south share a room and a target, so the same output but for
	# south's fault: the cover's chart must still show north's line (purple)
	# beside south's (orange) drawn over it
	"$BIN/psensctl" -d "$TMP/site.db" report -c config/example/site.conf --page 1 -o "$TMP/cover.png" > /dev/null 2>&1
	set -- $(python3 tests/system/pngcolours.py "$TMP/cover.png" 115,51,153 224,122,0)
	check "the cover's chart shows north's line under south's: $1 purple pixels, $2 orange (at least half)" \
		test "$1" -gt 0 -a "$((2 * $1))" -ge "$2"
else
	skip "pdftotext not installed"
fi
check "psvirt's summary per zone: $(grep -c '^psvirt: zone' "$TMP/site.out") zones" test "$(grep -c '^psvirt: zone' "$TMP/site.out")" = 3
done_testing
