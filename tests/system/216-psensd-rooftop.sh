#!/bin/sh
# SPDX-License-Identifier: ISC
# The live estimate's sky class from a rooftop sensor: the loopback room
# plays a date of the synthetic year ([simulate] year = yes) and serves the
# hour's global horizontal illuminance on a point with role rooftop; the
# zone's rooftop key makes the dated estimate classify the sky from it
# (clearness index, Erbs, Perez epsilon) instead of the month's typical
# class.  Checked against the weather file's own classes (psscene's, from
# its direct and diffuse irradiance: a route the rooftop never sees) on an
# overcast and a clear July date, and against the typical class's estimate
# error (psensd -s's "estimated against true task illuminance", the room's
# truth) on both dates.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
example_results
# this test needs a known day shape: the synthetic year's overcast 5 July in
# a mostly clear July (tests/data/weather/README.md), not the example's
# measured year
cp tests/data/weather/sf-synthetic.wea "$TMP/example/ofb/weather/"
sed -i 's|^weather = .*|weather = ofb/weather/sf-synthetic.wea|' "$TMP/example/ofb.scene"
"$BIN/psscene" -q -N -o "$TMP/state/ofb.results" "$TMP/example/ofb.scene"
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|; s/^faults = .*//; s/^\[simulate\]/[simulate]\nyear = yes/" \
	config/psensd.conf > "$TMP/typical.conf"
printf '\n[point roof]\ndevice = room\nrole = rooftop\n' >> "$TMP/typical.conf"
sed 's/^\[zone office\]/[zone office]\nrooftop = roof/' "$TMP/typical.conf" > "$TMP/rooftop.conf"
check "the results carry the weather's site" grep -q "^latitude = 37.6" "$TMP/state/ofb.results"
# the weather's own class of every hour of a date between two hours (standard time)
weather_classes() {   # month day from to
	awk -v m="$1" -v d="$2" -v a="$3" -v b="$4" '/^\[year_hours\]/ { f = 1; next } /^\[/ { f = 0 }
		f && /^h[0-9]/ { split($0, kv, " = "); split(kv[2], v, " ")
			if (v[1] == m && v[2] == d && v[3] >= a && v[3] <= b) s = s v[6] } END { print s }' "$TMP/state/ofb.results"
}
rms() { sed -n 's/.*estimated against true task illuminance:.*rms \([0-9.]*\) %.*/\1/p' "$1"; }
# day: date month day from_s to_s class classname min_percent: at least
# min_percent of the good samples in the window judge the sky as the
# weather does
day() {
	sed "s/^date = .*/date = $1/" "$TMP/typical.conf" > "$TMP/t-$1.conf"
	sed "s/^date = .*/date = $1/" "$TMP/rooftop.conf" > "$TMP/r-$1.conf"
	rm -f "$TMP/state/psensd.db"*
	"$BIN/psensd" -f "$TMP/t-$1.conf" -s > "$TMP/t-$1.out" 2>&1
	check "$1: the typical class runs" test $? = 0
	rm -f "$TMP/state/psensd.db"*
	"$BIN/psensd" -f "$TMP/r-$1.conf" -s > "$TMP/r-$1.out" 2>&1
	check "$1: the rooftop class runs" test $? = 0
	n=$(sqlite3 "$TMP/state/psensd.db" "select count(*) from samples where fault is null and tod_s between $4 and $5")
	k=$(sqlite3 "$TMP/state/psensd.db" "select count(*) from samples where fault is null and tod_s between $4 and $5 and condition = 'daylight_rooftop_$7'")
	check "$1: $k of $n good samples $(($4 / 3600))h-$(($5 / 3600))h judge the sky $7 (at least $8 %)" \
		test "$n" -gt 60 -a "$((100 * k))" -ge "$(($8 * n))"
	t=$(rms "$TMP/t-$1.out"); r=$(rms "$TMP/r-$1.out")
	echo "# $1: estimate rms error $t % with the typical class, $r % with the rooftop's"
	check "$1: the rooftop's estimate rms $r % below the typical class's $t %" \
		awk -v t="$t" -v r="$r" 'BEGIN { exit !(r != "" && t != "" && r + 0 < t + 0) }'
}
# 07-05 is overcast all day (epsilon 1: no direct light), but bright: at
# noon 52.7 klx, kt 0.42, which Erbs's correlation reads as 80 % diffuse,
# epsilon 1.25, just intermediate; one number cannot tell a bright overcast
# from a hazy sun, so 12 of 541 samples near 12:30 judge intermediate.
day 07-05 7 5 28800 61200 2 overcast 95
day 07-01 7 1 43200 59400 0 clear 100
# the weather's classes there, independently of the rooftop route
check "07-05 08h-17h: the weather says overcast every hour" test -z "$(weather_classes 7 5 7.5 17.5 | tr -d 2)"
check "07-01 12h-16:30: the weather says clear every hour" test -z "$(weather_classes 7 1 11.5 16.5 | tr -d 0)"
check "07-01 has those hours" test "$(weather_classes 7 1 11.5 16.5 | wc -c)" -ge 6
# a rooftop point where the zone needs one of another role: refused with the line
sed 's/^rooftop = roof/rooftop = room/' "$TMP/rooftop.conf" > "$TMP/bad.conf"
"$BIN/psensd" -f "$TMP/bad.conf" -n > /dev/null 2> "$TMP/bad.err"
check "rooftop naming no point fails" test $? -ne 0
check "and names the key" grep -q "rooftop: no \[point room\]" "$TMP/bad.err"
# the clear-sky profile (no year) has no rooftop reading: logged, the typical class used
sed '/^year = yes/d; s/^\[psensd\]/[psensd]\nestimate = dated/' "$TMP/rooftop.conf" > "$TMP/noyear.conf"
rm -f "$TMP/state/psensd.db"*
"$BIN/psensd" -f "$TMP/noyear.conf" -s > /dev/null 2> "$TMP/noyear.err"
check "a room without a rooftop reading still runs" test $? = 0
check "and says once that the typical class is used" test "$(grep -c "rooftop roof: .*the typical sky class until it reads" "$TMP/noyear.err")" = 1
done_testing
