#!/bin/sh
# SPDX-License-Identifier: ISC
# Summer time: the results' year, its dated ratio table and the weather's
# hours are standard time, while psensd's clock (and every sample's local
# column) is local time.  A simulated day of the year in Los Angeles on 26
# June (PDT, an hour ahead of standard time) must therefore play and
# estimate at 13:00 local exactly what a zone on fixed Pacific standard time
# (Etc/GMT+8) plays and estimates at 12:00: the same hour of the weather and
# the same ratio.  In January the two zones agree at the same clock time.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 >/dev/null 2>&1 || skip_all "sqlite3 not installed"
[ -f /usr/share/zoneinfo/America/Los_Angeles ] || skip_all "no tzdata for America/Los_Angeles"
mkdir -p "$TMP/example" "$TMP/state"
cp -R config/example/ofb config/example/ofb.scene "$TMP/example/"
run_day() {   # TZ DATE: the database's (local time, ratio, daylight lux) rows
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/$1.db|;
	     s|^date = .*|date = ${2#*-}\nyear = yes|; s|^faults = .*||" config/psensd.conf > "$TMP/$1.conf"
	rm -f "$TMP/state/$1.db"
	(cd "$TMP" && TZ=$3 PATH="$TOP/$BIN:$PATH" "$TOP/$BIN/psensd" -f "$1.conf" -s -d "$2" > "$1.out" 2>&1) ||
		{ cat "$TMP/$1.out" >&2; return 1; }
}
# rows of a run as "local-time-shifted-by-H ratio", H hours subtracted from local
rows() {
	sqlite3 -separator ' ' "$TMP/state/$1.db" \
		"select time(substr(local, 12), '-$2 hours'), printf('%.9g', ratio) from samples
		 where substr(local, 12, 5) between '$3' and '$4' order by utc"
}
check "a summer day in Los Angeles" run_day la-summer 2026-06-26 America/Los_Angeles
check "the same day on Pacific standard time" run_day pst-summer 2026-06-26 Etc/GMT+8
rows la-summer 1 08:00 17:00 > "$TMP/la"
rows pst-summer 0 07:00 16:00 > "$TMP/pst"
check "the rows compared: $(wc -l < "$TMP/la") samples" test "$(wc -l < "$TMP/la")" -gt 500
check "13:00 PDT estimates with 12:00 PST's dated ratio (every sample 08:00-17:00 PDT)" cmp "$TMP/la" "$TMP/pst"
la13=$(sqlite3 "$TMP/state/la-summer.db" "select printf('%.4f', daylight_v) from samples where local like '% 13:00:00'")
pst12=$(sqlite3 "$TMP/state/pst-summer.db" "select printf('%.4f', daylight_v) from samples where local like '% 12:00:00'")
pst13=$(sqlite3 "$TMP/state/pst-summer.db" "select printf('%.4f', daylight_v) from samples where local like '% 13:00:00'")
check "the room at 13:00 PDT plays 12:00 PST's weather: sensor daylight $la13 V (12:00 PST $pst12, 13:00 PST $pst13)" \
	awk -v a="$la13" -v b="$pst12" -v c="$pst13" 'BEGIN { exit !(a > 0 && (a - b) ^ 2 < (a - c) ^ 2 && (a / b - 1) ^ 2 < 1e-4) }'
# winter: no summer time, the same clock time
check "a winter day in Los Angeles" run_day la-winter 2026-01-15 America/Los_Angeles
check "the same day on Pacific standard time" run_day pst-winter 2026-01-15 Etc/GMT+8
rows la-winter 0 08:00 16:00 > "$TMP/law"
rows pst-winter 0 08:00 16:00 > "$TMP/pstw"
check "in January the two agree at the same clock time" cmp "$TMP/law" "$TMP/pstw"
done_testing
