#!/bin/sh
# SPDX-License-Identifier: ISC
# A simulated day through psvirt: psensd's set-point control law (mbdrive
# control) on the real Modbus driver over TCP, psvirt running the room at
# 3600x real time (05:00 to about 19:00 in 14 s), one step per 15 simulated
# minutes.  Checked against the scene's numbers: at night the level is
# target / electric task lux; in bright daylight the minimum level; the
# room's open-circuit fault 12:00-12:30 and an injected late reply both send
# the lights to the safe level, and control resumes.  The ballast is instant:
# the truth is read just after each step (at 3600x a fade of 0.2/s would
# still be under way a round trip later), so the check is of the control's
# accuracy, not of how far dusk falls within a 15-minute period.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need mbpoll
make_results
L=$(summary electric_task_lux)
port=$(free_port)
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
	--date 03-18 --sunrise 06:00 --sunset 18:30 --start 05:00 --speed 3600 \
	-D gain=0.5 -D noise=0.002 -D task_noise=2 -D seed=7 -D fade_rate=0 -D lag_tau=0 -D min_level=0.1 \
	-o "faults=open 12:00-12:30" > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
pv=$!
track_pid $pv
check "psvirt ready" wait_for 10 test -s "$TMP/ready"
{ device_tcp "$port" timeout=0.2 retries=1 backoff_min=0.1; points; cat <<EOC
[control]
results = $TMP/ofb.results
period = 0.25
target_lux = 500
sensor_gain = 0.5
min_level = 0.1
safe_level = 1
EOC
} > "$TMP/day.conf"
"$MBDRIVE" "$TMP/day.conf" control 14 > "$TMP/day.out" 2> "$TMP/day.err" &
md=$!
track_pid $md
# at 08:00 room time, a late reply for two requests (both tries of one read)
at8() { awk '/^tod=(0[89]|1[0-9])/ { f = 1 } END { exit !f }' "$TMP/day.out"; }
check "the day reaches 08:00" wait_for 10 at8
mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 902 -t 4 127.0.0.1 400 > /dev/null &&
	mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 901 -t 4 127.0.0.1 2 > /dev/null &&
	mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 900 -t 4 127.0.0.1 1 > /dev/null
check "late replies injected through the fault registers" test $? = 0
wait_for 20 sh -c "! kill -0 $md 2>/dev/null"
check "the control run ended: $(tail -n 1 "$TMP/day.out")" grep -q "^control: " "$TMP/day.out"
kill "$pv"; wait "$pv"
diag "$(cat "$TMP/psvirt.out")"
diag "$(grep -e fault -e "^tod=1[78]" "$TMP/day.out")"
# night, before sunrise: the electric light alone holds the target
want=$(awk -v l="$L" 'BEGIN { print 500 / l }')
night=$(awk '/^tod=05:[1-5]/ && !/fault/ { sub("level=", "", $3); print $3; exit }' "$TMP/day.out")
check "before sunrise the level is 500 lx / $L lx = $want ($night)" near "$night" "$want" 0.01
noon=$(awk '/^tod=1[01]:/ && !/fault/ { sub("level=", "", $3); if ($3 > m) m = $3 } END { print m + 0 }' "$TMP/day.out")
check "10:00-12:00 the daylight is enough: the minimum level 0.1 (highest $noon)" near "$noon" 0.1 1e-9
check "the open circuit at 12:00 is a fault at the safe level" grep -q "^tod=12:[0-2].*level=1.0000.*fault=range sensor reads 0.000 V" "$TMP/day.out"
check "after 12:30 control resumes" grep -q "^tod=1[34]:.*level=0.1000 truth" "$TMP/day.out"
check "the late reply: ETIMEDOUT, safe level: $(grep -m1 ETIMEDOUT "$TMP/day.out")" \
	grep -q "level=1.0000.*fault=ETIMEDOUT modbus io unit 1 IR 0: no reply within 0.200 s" "$TMP/day.out"
after=$(awk '/ETIMEDOUT/ { f = 1; next } f && !/fault/ { print; exit }' "$TMP/day.out")
check "and the next step controls again: $after" test -n "$after"
# the occupants' light: judged steps below target (2 %), from the room's truth
line=$(tail -n 1 "$TMP/day.out")
below=$(echo "$line" | sed -n 's/.*, \([0-9]*\) of \([0-9]*\) judged.*/\1/p')
judged=$(echo "$line" | sed -n 's/.*, \([0-9]*\) of \([0-9]*\) judged.*/\2/p')
check "at most 2 of $judged steps below target ($below)" awk -v b="$below" -v j="$judged" 'BEGIN { exit !(j >= 40 && b <= 2) }'
energy=$(sed -n 's/.*light output \([0-9.]*\) % of full.*/\1/p' "$TMP/psvirt.out")
check "daylight saves: $energy % of full output over the day" awk -v e="$energy" 'BEGIN { exit !(e > 10 && e < 50) }'
done_testing
