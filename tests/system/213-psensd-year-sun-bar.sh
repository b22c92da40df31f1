#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd -Y's error bar on the sun's placement is computed for the scene it
# runs, not quoted from one office: psscene writes every hour of the year
# with the sun shared among four patches and with it in its nearest patch,
# and -Y prints how far the occupied hours' task daylight moves between the
# two.  Two scenes (the example office over San Francisco's TMY3 year, and
# the same office over the synthetic year) give two different bars, and
# each bar's hourly figures (largest, 95th percentile, median, hours, the
# sum) equal an awk computation straight from the results file's hours
# (08:00-18:00 standard time, 50 lx or more).  Results without the second
# placement (an older psscene's) give no bar and -Y says so; the example
# office's fixed figures are gone from the output.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
cp tests/data/weather/sf-synthetic.wea "$TMP/example/ofb/weather/synthetic.wea"
sed "s|^weather = .*|weather = ofb/weather/synthetic.wea|" "$TMP/example/ofb.scene" > "$TMP/example/syn.scene"
"$BIN/psscene" -q -N -o "$TMP/state/syn.results" "$TMP/example/syn.scene"
check "psscene runs the synthetic year" test $? = 0
conf() {   # conf NAME
	sed "s|^results = .*|results = $TMP/state/$1.results|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $TMP/example/$1.scene|" \
		config/psensd.conf
}
# the bar's hourly figures from the results' hours, printed as -Y prints them
expect() {
	awk '/^\[year_hours\]/ { on = 1; next } /^\[/ { on = 0 }
	     on && /^h[0-9]+ = / && NF == 12 {
		hour = $5; task = $7; alt = $12
		if (hour * 3600 >= 8 * 3600 && hour * 3600 < 18 * 3600 && task >= 50) {
			d[m++] = alt / task - 1; if (d[m - 1] < 0) d[m - 1] = -d[m - 1]
			s0 += task; s1 += alt
		}
	     }
	     END {
		for (i = 1; i < m; i++) { v = d[i]; for (j = i - 1; j >= 0 && d[j] > v; j--) d[j + 1] = d[j]; d[j + 1] = v }
		printf "by up to %.0f %%|(95th percentile %.1f %%, median %.1f %%; %.0f hours with 50 lx or more), their sum|by %+.2f %%;\n",
		       100 * d[m - 1], 100 * d[int(0.95 * (m - 1))], 100 * d[int((m - 1) / 2)], m, 100 * (s1 / s0 - 1)
	     }' "$1"
}
has() { printf '%s\n' "$1" | grep -qF -- "$2"; }
bars=""
for y in ofb syn; do
	conf $y > "$TMP/$y.conf"
	(cd "$TMP" && "$TOP/$BIN/psensd" -f "$y.conf" -Y) > "$TMP/$y.out" 2>&1
	check "$y: -Y runs the year" test $? = 0
	check "$y: -Y labels the bar an estimate from the scene's coefficients" \
		grep -q "an estimate of its error from this scene's coefficients" "$TMP/$y.out"
	check "$y: no fixed example-office figure" sh -c "! grep -q 'independent MF 4 route\|80 %% (95th' '$TMP/$y.out'"
	e=$(expect "$TMP/state/$y.results")
	got=$(sed -n '/the sun in its nearest patch moves/,/below 90 %/p' "$TMP/$y.out" | tr '\n' ' ')
	diag "$y: $(echo "$got" | tr -s ' ')"
	ok1=$(echo "$e" | cut -d'|' -f1)
	ok2=$(echo "$e" | cut -d'|' -f2)
	ok3=$(echo "$e" | cut -d'|' -f3)
	check "$y: largest hour as computed from the results ($ok1)" has "$got" "$ok1"
	check "$y: percentiles and hours as computed ($ok2)" has "$got" "$ok2"
	check "$y: the sum as computed ($ok3)" has "$got" "$ok3"
	bars="$bars|$ok1 $ok2"
done
b1=$(echo "$bars" | cut -d'|' -f2)
b2=$(echo "$bars" | cut -d'|' -f4)
check "two scenes, two bars" test "$b1" != "$b2"
# results from a psscene that wrote no second placement: no estimate, said so
awk '/^\[year_hours\]/ { on = 1 } /^\[ratio_table\]/ { on = 0 }
     on && /^h[0-9]+ = / && NF == 12 { NF = 10 } { print }' "$TMP/state/ofb.results" > "$TMP/state/old.results"
sed "s|^results = .*|results = $TMP/state/old.results|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
	config/psensd.conf > "$TMP/old.conf"
(cd "$TMP" && "$TOP/$BIN/psensd" -f old.conf -Y) > "$TMP/old.out" 2>&1
check "results without the second placement: -Y runs" test $? = 0
check "and says there is no estimate" grep -q "the sun's placement: no estimate of its error" "$TMP/old.out"
done_testing
