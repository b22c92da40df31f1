#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd -n refuses what would wreck a run later, each at the file and line:
# a period shorter than a device can answer in and the log can hold (a
# millisecond typo wrote hundreds of megabytes a minute), the other duration
# keys bounded the same way, a database, socket or textfile in a directory
# that is missing or not writable (the daemon would refuse to start with the
# lights at the safe level), and a simulated date that is not in the
# calendar.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
mkdir -p "$TMP/site" "$TMP/site/ro"
cp "$TMP/state/ofb.results" "$TMP/site/r.results"
chmod a-w "$TMP/site/ro"
conf() { # NAME, then the [psensd] lines on stdin; one loopback zone
	{ printf '[psensd]\nresults = r.results\n'; cat
	  printf '[device room]\ndriver = loopback\n[zone office]\ndevice = room\n'; } > "$TMP/site/$1.conf"
}
judge() { "$BIN/psensd" -n -f "$TMP/site/$1.conf" > "$TMP/$1.out" 2>&1; echo $?; }

printf 'database = db.sqlite\nsocket = sock\nperiod = 0.1\n' | conf good
rc=$(judge good)
check "a good configuration at the shortest period passes (exit $rc): $(cat "$TMP/good.out")" test "$rc" = 0

# period: 0.001 s is a typo for 1 s or 60 s
printf 'period = 0.001\n' | conf ms
rc=$(judge ms); diag "$(cat "$TMP/ms.out")"
check "period = 0.001 is refused (exit $rc)" test "$rc" = 1
check "at its line, with the bound and the reason" \
	grep -q "ms.conf:3: period: 0.001 s is shorter than 0.1 s.*device.*log" "$TMP/ms.out"
printf 'period = 0.05\n' | conf ms2
rc=$(judge ms2)
check "period = 0.05 is refused too (exit $rc)" test "$rc" = 1
# the zone's own period and the calibration's durations have the same floor
{ printf '[psensd]\nresults = r.results\n[device room]\ndriver = loopback\n[zone office]\ndevice = room\n'
  printf 'period = 0.002\ncal_window = 0.01\ncal_day_interval = 0.001\n'; } > "$TMP/site/zone.conf"
rc=$(judge zone); diag "$(cat "$TMP/zone.out")"
check "a zone's period, cal_window, cal_day_interval below the floor: each at its line (exit $rc)" \
	test "$rc" = 1 -a "$(grep -c 'zone.conf:[789]: [a-z_]*: 0.0[0-9]* s is shorter than 0.1 s' "$TMP/zone.out")" = 3

# output files in missing or read-only directories
printf 'database = no-such-dir/psensd.db\nsocket = ro/sock\n[prometheus]\ntextfile = gone/psensd.prom\n' | conf out
rc=$(judge out); diag "$(cat "$TMP/out.out")"
check "outputs in missing or read-only directories are refused (exit $rc)" test "$rc" = 1
check "the database's missing directory, at its line" \
	grep -q "out.conf:3: database: .*site/no-such-dir: No such file or directory" "$TMP/out.out"
if [ "$(id -u)" != 0 ]; then
	check "the socket's read-only directory, at its line" \
		grep -q "out.conf:4: socket: .*site/ro: .*not writable" "$TMP/out.out"
else
	skip "root writes a read-only directory"
fi
check "the textfile's missing directory, at its line" \
	grep -q "out.conf:6: textfile: .*site/gone: No such file or directory" "$TMP/out.out"

# simulated dates: 02-29 is a day (a leap year's weather plays it), 02-30 is not
for d in 02-30 04-31 13-01 00-10; do
	{ printf '[psensd]\nresults = r.results\n[simulate]\ndate = %s\n' "$d"
	  printf '[device room]\ndriver = loopback\n[zone office]\ndevice = room\n'; } > "$TMP/site/d.conf"
	rc=$(judge d)
	check "date = $d is refused at its line (exit $rc): $(cat "$TMP/d.out")" \
		grep -q "d.conf:4: date: '$d' is not a day of the year" "$TMP/d.out"
done
printf '[psensd]\nresults = r.results\n[simulate]\ndate = 02-29\n[device room]\ndriver = loopback\n[zone office]\ndevice = room\n' \
	> "$TMP/site/d.conf"
rc=$(judge d)
check "date = 02-29 passes (exit $rc)" test "$rc" = 0
chmod u+w "$TMP/site/ro"
done_testing
