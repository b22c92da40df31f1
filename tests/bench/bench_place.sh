#!/bin/sh
# SPDX-License-Identifier: ISC
# The pose search (psplace): combinations (poses x rotations x sensors x
# laws) scored over the weather year with the real law and device model,
# from the projections made once per pose.  Goals: the example office's
# table, 11 poses x 36 rotations x 3 sensors x 5 laws, in at most 2 s; and
# 10,000 combinations over the year's 8760 hours in at most 10 s.  Prints
# where the time goes (psplace's own "time:" line) and, with /usr/bin/time,
# the CPU time of the whole run and per combination (on a machine shared
# with other jobs the wall time says little; the CPU time over the two
# cores says what two free cores would take).  The eleven poses are the
# placement fixture's (PSPLACE_FULL, default ../shared/fixtures/ofb-place
# beside the tree); without it, the three poses of tests/data/ofb-place.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
tmp=$(mktemp -d /tmp/psplace.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
D=tests/data/ofb-place
FULL=${PSPLACE_FULL:-../shared/fixtures/ofb-place}
if [ -f "$FULL/candidates.txt" ]; then
	cands=$FULL/candidates.txt dir=$FULL
else
	echo "bench_place: no full fixture at $FULL: the three poses of $D"
	mkdir -p "$tmp/poses"
	for p in p01 p07 p09; do tar -xzf "$D/$p.tar.gz" -C "$tmp/poses"; done
	cands=$D/candidates.txt dir=$tmp/poses
fi
awk 'BEGIN { printf "Elevation field 90\ndegrees\t0\t90\t180\t270\n";
	for (t = 0; t <= 90; t += 10) { c = cos(t * 3.14159265358979 / 180); if (t == 90) c = 0;
		printf "%d\t%.6f\t%.6f\t%.6f\t%.6f\n", t, 1.9 * c, c, 0.1 * c, c } }' > "$tmp/lopsided.sen"
S="config/example/ofb/sensors"
timed() {
	if [ -x /usr/bin/time ]; then
		/usr/bin/time -f "%U %S %e" -o "$tmp/time" "$@"
	else
		rm -f "$tmp/time"
		"$@"
	fi
}
run() {
	what=$1; shift
	timed "$BIN/psplace" -f config/psensd.conf -c "$cands" -d "$dir" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
		-w config/example/ofb/weather/sf-tmy3.wea -T 3 -q "$@" > "$tmp/out" 2>&1 || { cat "$tmp/out"; exit 1; }
	echo "$what:"
	sed -n 's/^psplace: zone [^,]*, \(.*combinations\),$/  \1/p; s/^\(time: .*\)$/  \1/p; s/^\(exact route, rank 1: .*\)$/  \1/p' "$tmp/out"
	n=$(sed -n 's/^psplace: zone .* = \([0-9]*\) combinations,$/\1/p' "$tmp/out")
	[ ! -f "$tmp/time" ] || [ -z "$n" ] || awk -v n="$n" '{ printf "  cpu: %.2f s user + %.2f s system in %.2f s of wall time: %.3f ms of CPU a combination\n",
			$1, $2, $3, 1000 * ($1 + $2) / n }' "$tmp/time"
}
run "a year at the zone's period (60 s: 525,600 steps), 4 rotations, one sensor" -r 90 -s builtin:cosine
run "the example office, hourly steps" -r 10 -s builtin:cosine -s $S/cone.sen -s "$tmp/lopsided.sen" -p 3600
run "about 10,000 combinations, hourly steps" -r 10 -s builtin:cosine -s $S/cone.sen -s "$tmp/lopsided.sen" \
	-s $S/cosine.sen -s builtin:uniform -p 3600
