#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd over the example's year: -Y runs every zone's law against the room
# playing each day of the results' year and prints the annual figures, the
# laws side by side and (with -P) the year as a PNG; results without a year
# are refused clearly; a simulated day of the year ([simulate] year = yes)
# logs the dated estimate.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
	config/psensd.conf > "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -Y -P "$TMP/year.png" > "$TMP/out" 2> "$TMP/err"
check "-Y runs" test $? = 0
check "a year at 60 s is 525,600 steps" grep -q "525600 control steps" "$TMP/out"
check "3650 occupied hours" grep -q "occupied 08:00-18:00 every day, 3650 h" "$TMP/out"
for what in "lighting energy" "ideal photocell (DAYSIM" "below 90 % of target" "dimming changes an hour" \
	"one mean ratio" "dated ratio (month x hour x typical sky class)"; do
	check "prints: $what" grep -qF "$what" "$TMP/out"
done
check "a monthly table of 12 months" test "$(grep -cE '^  (Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec) ' "$TMP/out")" = 12
for alg in setpoint closed-proportional open-proportional integral-reset switching; do
	check "the laws compared: $alg" grep -qE "^  $alg +[0-9.]+ " "$TMP/out"
done
check "the year drawn as a PNG" sh -c "head -c 8 '$TMP/year.png' | od -An -c | grep -q 'P   N   G'"
# The picture's layout (annual.c): panels 2 px a day from x 50 and 2 px per
# 10 minutes, the task panel from y 52, the output panel from y 402.  Lit
# output and off must be told apart at a glance: 19 June at 12:00 (the
# lights at their minimum in a daylit room) against 03:00 (off), more than
# 100 apart in RGB; a linear grey put them 21 apart.
px() { python3 tests/system/pngcolours.py --at "$TMP/year.png" "$1"; }
dist() { echo "$1 $2" | awk '{ split($1, a, ","); split($2, b, ",");
	print int(sqrt((a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2 + (a[3] - b[3]) ^ 2)) }'; }
noon=$(px 390,544); night=$(px 390,652); late=$(px 390,424)
check "the output panel: off at 03:00 ($night) and at 22:00 ($late) alike" test "$night" = "$late"
check "the output panel: lit at noon ($noon) apart from off at 03:00 ($night)" test "$(dist "$noon" "$night")" -gt 100
# month names under the task panel too (ink in December's label's box)
ink=$(python3 tests/system/pngcolours.py "$TMP/year.png" 0,0,0 | head -n 1)
dec=$(python3 - "$TMP/year.png" <<'PY'
import subprocess, sys
pts = ['%d,%d' % (x, y) for x in range(736, 762) for y in range(342, 356)]
out = subprocess.run(['python3', 'tests/system/pngcolours.py', '--at', sys.argv[1]] + pts,
                     capture_output=True, text=True).stdout.split()
print(sum(1 for p in out if sum(int(v) for v in p.split(',')) < 300))
PY
)
check "month names under the task panel (Dec: $dec dark pixels; $ink black in all)" test "$dec" -gt 5
# the dated estimate beats the one mean ratio over the example's year
rms() { sed -n "s/.*$1.*rms \([0-9.]*\) %.*/\1/p" "$TMP/out" | head -n 1; }
m=$(rms "one mean ratio"); d=$(rms "dated ratio")
check "dated estimate rms $d % below the mean ratio's $m %" awk -v m="$m" -v d="$d" 'BEGIN { exit !(d < m) }'
# and the sky class from a rooftop reading beats the typical class
g=$(rms "sky class from a rooftop sensor")
check "rooftop class estimate rms $g % below the typical class's $d %" awk -v g="$g" -v d="$d" 'BEGIN { exit !(g != "" && g < d) }'
# an effectiveness above 100 % says why next to it: integral reset on the
# example saves more than the ideal photocell by leaving the task short of
# its target; the hours, the lux and the effectiveness at target are given
sed 's/^algorithm = .*/algorithm = integral-reset/' "$TMP/psensd.conf" > "$TMP/ir.conf"
"$BIN/psensd" -f "$TMP/ir.conf" -Y > "$TMP/ir.out" 2>&1
eff=$(sed -n 's/^  ideal photocell.*effectiveness \([0-9.]*\) %$/\1/p' "$TMP/ir.out")
sed -n '/^  ideal photocell/,/^  occupied hours below/p' "$TMP/ir.out" | tr '\n' ' ' | tr -s ' ' > "$TMP/ir.why"
check "integral reset's effectiveness is above 100 % ($eff %)" awk -v e="$eff" 'BEGIN { exit !(e > 100) }'
check "and says why next to it: $(cat "$TMP/ir.why")" grep -q "above 100 % by under-lighting: [0-9.]* occupied hours with the task short of the 500 lx target, by [0-9]* lx" "$TMP/ir.why"
att=$(sed -n 's/.*lighting delivered at target): \([0-9.]*\) %.*/\1/p' "$TMP/ir.why")
check "its effectiveness at target ($att %) below the figure ($eff %)" awk -v a="$att" -v e="$eff" 'BEGIN { exit !(a != "" && a < e) }'
check "the laws' table gives the effectiveness at target" grep -q "effect. %  at tgt %" "$TMP/ir.out"
# the occupied hours from [simulate]
sed 's/^\[simulate\]/[simulate]\noccupied_from = 09:00\noccupied_to = 17:00/' "$TMP/psensd.conf" > "$TMP/occ.conf"
"$BIN/psensd" -f "$TMP/occ.conf" -Y > "$TMP/occ.out" 2>&1
check "occupied_from and occupied_to: 2920 h" grep -q "occupied 09:00-17:00 every day, 2920 h" "$TMP/occ.out"
# results without a year: refused, naming what is missing
sed '/^weather = /d' "$TMP/example/ofb.scene" > "$TMP/example/noyear.scene"
"$BIN/psscene" -q -N -o "$TMP/state/noyear.results" "$TMP/example/noyear.scene"
sed "s|^results = .*|results = $TMP/state/noyear.results|; s|^scene = .*|scene = $TMP/example/noyear.scene|" \
	"$TMP/psensd.conf" > "$TMP/noyear.conf"
"$BIN/psensd" -f "$TMP/noyear.conf" -Y > /dev/null 2> "$TMP/err2"
check "-Y without a year fails" test $? -ne 0
check "and says a weather file is needed" grep -q "needs results with a year" "$TMP/err2"
sed 's/^\[simulate\]/[simulate]\nyear = yes/' "$TMP/noyear.conf" > "$TMP/noyear-day.conf"
"$BIN/psensd" -f "$TMP/noyear-day.conf" -s > /dev/null 2> "$TMP/err3"
check "a day of the year without a year fails" test $? -ne 0
check "and names what is missing" grep -q "year = yes needs results with a year" "$TMP/err3"
# a simulated day of the year logs the dated ratio
sed 's/^\[simulate\]/[simulate]\nyear = yes/' "$TMP/psensd.conf" > "$TMP/day.conf"
"$BIN/psensd" -f "$TMP/day.conf" -s > "$TMP/day.out" 2> "$TMP/day.err"
check "a simulated day of the year runs" test $? = 0
check "its samples name the dated ratio" sh -c "sqlite3 '$TMP/state/psensd.db' \"select count(*) from samples where condition = 'daylight_dated'\" | grep -qv '^0$'"
# estimate = mean holds even when the room plays the year
sed 's/^\[psensd\]/[psensd]\nestimate = mean/' "$TMP/day.conf" > "$TMP/mean.conf"
rm -f "$TMP/state/psensd.db"*
"$BIN/psensd" -f "$TMP/mean.conf" -s > /dev/null 2>&1
check "estimate = mean: the samples name the mean ratio" sh -c "sqlite3 '$TMP/state/psensd.db' \"select count(*) from samples where condition = 'daylight_dated'\" | grep -q '^0$' && sqlite3 '$TMP/state/psensd.db' \"select count(*) from samples where condition = 'daylight_mean'\" | grep -qv '^0$'"
done_testing
