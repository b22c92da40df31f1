#!/bin/sh
# SPDX-License-Identifier: ISC
# Every control algorithm over the example day on the loopback room: the
# ones that use both calibrations hold the target, integral reset
# under-lights (the sensor sees relatively more daylight than the desk, as
# the literature reports), switching keeps to its deadband.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
below() { sed -n 's/.*time below target (by more than 2 %): \([0-9.]*\) %.*/\1/p' "$1"; }
for alg in setpoint closed-proportional open-proportional integral-reset switching; do
	sed "s|^results = .*|results = state/ofb.results|; /^database = /d; s|^algorithm = .*|algorithm = $alg|; /^faults = /d" \
		config/psensd.conf > "$TMP/$alg.conf"
	[ "$alg" = switching ] && printf 's_off = 3.2\ns_on = 2.2\ndelay = 600\nsteps = 2\n' >> "$TMP/$alg.conf"
	"$BIN/psensd" -f "$TMP/$alg.conf" -s > "$TMP/$alg.out" 2> "$TMP/$alg.err"
	check "$alg runs the day: $(grep energy "$TMP/$alg.out")" grep -q "$alg control" "$TMP/$alg.out"
done
check "setpoint never below target" test "$(below "$TMP/setpoint.out")" = 0.0
check "closed-proportional below target at most 1 % of the day" awk -v b="$(below "$TMP/closed-proportional.out")" 'BEGIN { exit !(b <= 1) }'
check "integral reset under-lights part of the day ($(below "$TMP/integral-reset.out") %)" awk -v b="$(below "$TMP/integral-reset.out")" 'BEGIN { exit !(b > 5) }'
check "switching in two steps never under-lights here" test "$(below "$TMP/switching.out")" = 0.0
cp "$TMP/setpoint.conf" "$TMP/bad.conf"
printf 's_off = 1\ns_on = 2\n' >> "$TMP/bad.conf"
"$BIN/psensd" -f "$TMP/bad.conf" -n 2> "$TMP/bad.err" > /dev/null
check "s_on above s_off is refused" grep -q "s_on must not exceed s_off" "$TMP/bad.err"
done_testing
