#!/bin/sh
# SPDX-License-Identifier: ISC
# Several sensors in one psens run (-s repeated): each picture is decoded
# once for all of them (sim/weights/stream.h, ps_stream_integrate_multi).  Every
# sensor's JSON object equals psens with that sensor alone (the same
# printed digits: the sums are the same bit for bit), for a symmetric
# builtin, its table twin and a table that changes with azimuth, turned by
# -r 20, over pictures of two sizes, with 1 and 2 threads and with the
# cache; an unreadable picture is named once and the others still come; a
# matrix of mixed sizes is refused as for one sensor.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] && [ -x "$BIN/mksens" ] || skip_all "psens or mksens not built"
I=config/example/ofb/img
cat >"$TMP/a.sen" <<'SEN'
Elevation field 90
degrees 0 45 90 135 180 225 270 315
0 1 1 1 1 1 1 1 1
20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9
40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75
60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5
80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1
90 0 0 0 0 0 0 0 0
SEN
"$BIN/mksens" -S 64 builtin:cosine >"$TMP/small.hdr"
set -- $I/day_0318_sensor_256.hdr "$TMP/small.hdr" $I/elec_sensor_256.hdr \
	$I/day_0416_task_256.hdr
S1=builtin:cosine
S2=config/example/ofb/sensors/cosine.sen
S3=$TMP/a.sen
for s in "$S1" "$S2" "$S3"; do
	"$BIN/psens" -q -N -j -r 20 -s "$s" "$@" >>"$TMP/alone"
done
check "alone: 3 sensors x $# pictures" test "$(grep -c '"response"' "$TMP/alone")" = $((3 * $#))
for n in 1 2; do
	"$BIN/psens" -q -N -j -n $n -r 20 -s "$S1" -s "$S2" -s "$S3" "$@" >"$TMP/both$n" 2>"$TMP/err"
	check "-n $n: exit 0" test $? = 0
	check "-n $n: one object per sensor and picture" \
		test "$(grep -c '"response"' "$TMP/both$n")" = $((3 * $#))
	# sensor by sensor, the "sensor" field taken out: the runs alone
	: >"$TMP/split$n"
	for s in "$S1" "$S2" "$S3"; do
		grep -F "\"sensor\": \"$s\"" "$TMP/both$n" | sed 's/, "sensor": "[^"]*"//' >>"$TMP/split$n"
	done
	check "-n $n: every object is the sensor's alone, to the printed digit" \
		cmp -s "$TMP/split$n" "$TMP/alone"
done
# lines: picture, sensor, in input order
first=$("$BIN/psens" -q -N -r 20 -s "$S2" -s "$S3" "$@" | head -n 2 | cut -d: -f1,2 | tr '\n' ' ')
check "lines: picture then sensor" test "$first" = "$1: $S2 $1: $S3 "
# through the cache, cold then warm: the same objects
for run in cold warm; do
	"$BIN/psens" -q -C "$TMP/cache" -j -r 20 -s "$S1" -s "$S2" -s "$S3" "$@" >"$TMP/$run"
	check "cache, $run: the same objects" cmp -s "$TMP/$run" "$TMP/both1"
done
# an unreadable picture: named once, the others given, exit 1
"$BIN/psens" -q -N -r 20 -s "$S1" -s "$S3" "$1" "$TMP/none.hdr" "$3" >"$TMP/out" 2>"$TMP/err"
check "missing picture: exit 1" test $? = 1
check "missing picture: named once" test "$(grep -c "$TMP/none.hdr" "$TMP/err")" = 1
check "missing picture: the others' four lines" test "$(grep -c Response "$TMP/out")" = 4
# a matrix of mixed sizes is refused, naming the file
"$BIN/psens" -q -N -oa -s "$S1" -s "$S3" "$1" "$TMP/small.hdr" >"$TMP/mixed" 2>"$TMP/err"
check "matrix of mixed sizes: exit 1, no matrix" sh -c "test \$? = 0 && test ! -s '$TMP/mixed'"
check "matrix of mixed sizes: the error names the file and both sizes" \
	grep -q "$TMP/small.hdr: picture is 64 x 64, the batch's weights are for 256 x 256" "$TMP/err"
done_testing
