#!/bin/sh
# SPDX-License-Identifier: ISC
# psens on many pictures (sim/weights/batch.h): the weights are built once and the
# pictures integrated in parallel; each result equals psens on that picture
# alone (the one-picture route), in input order, with 1 or 2 threads; the
# matrix output (-oa/-of/-od, Radiance's matrix format, one row for the
# sensor, one column per picture, components r g b) carries the same numbers
# and a correct header; a picture of another size in a matrix is an error
# naming its file, and no matrix is written.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] && [ -x "$BIN/mksens" ] || skip_all "psens or mksens not built"
I=config/example/ofb/img
set -- $I/day_0318_sensor_256.hdr $I/day_0416_task_256.hdr $I/elec_sensor_256.hdr \
	$I/day_0517_sensor_256.hdr $I/day_0318_task_256.hdr $I/elec_task_256.hdr
N=$#
# the one-picture route: each picture alone, its r g b as JSON gives them (%.10g)
: >"$TMP/alone"
for p in "$@"; do
	"$BIN/psens" -q -j -s builtin:cosine -r 20 "$p" |
		sed 's/.*"r": \([^,]*\), "g": \([^,]*\), "b": \([^,]*\),.*/\1 \2 \3/' >>"$TMP/alone"
done
check "$N one-picture results" test "$(grep -c . "$TMP/alone")" = "$N"
for n in 1 2; do
	"$BIN/psens" -q -n $n -oa -s builtin:cosine -r 20 "$@" >"$TMP/m$n.txt" 2>"$TMP/err"
	check "-n $n -oa: exit 0" test $? = 0
	# data: after the empty line ending the header, one line a column, an
	# empty line after the row
	sed '1,/^$/d' "$TMP/m$n.txt" | grep . >"$TMP/data$n"
	check "-n $n: the matrix's columns are the pictures alone, in order (10 digits)" \
		cmp -s "$TMP/data$n" "$TMP/alone"
done
check "header: NROWS=1" grep -qx 'NROWS=1' "$TMP/m2.txt"
check "header: NCOLS=$N" grep -qx "NCOLS=$N" "$TMP/m2.txt"
check "header: NCOMP=3" grep -qx 'NCOMP=3' "$TMP/m2.txt"
check "header: FORMAT=ascii" grep -qx 'FORMAT=ascii' "$TMP/m2.txt"
check "header: the command line" grep -q '^psens -q -n 2 -oa -s builtin:cosine' "$TMP/m2.txt"
check "header starts #?RADIANCE" test "$(head -n 1 "$TMP/m2.txt")" = '#?RADIANCE'
# -od: the same numbers as doubles, N x 3 x 8 bytes after the header
"$BIN/psens" -q -od -s builtin:cosine -r 20 "$@" >"$TMP/m.bin"
hlen=$(grep -a -b -m 1 -x '' "$TMP/m.bin" | cut -d: -f1)
total=$(wc -c <"$TMP/m.bin")
check "-od: $N x 3 doubles after the header" test $((total - hlen - 1)) = $((N * 24))
check "-od header: FORMAT=double" grep -aqx 'FORMAT=double' "$TMP/m.bin"
check "-od header: BYTEORDER" grep -aqx 'BYTEORDER=\(LittleEndian\|BigEndian\)' "$TMP/m.bin"
tail -c $((N * 24)) "$TMP/m.bin" | od -A n -v -t f8 | tr -s ' ' '\n' | grep . >"$TMP/od"
tr ' ' '\n' <"$TMP/alone" >"$TMP/alone1"
check "-od values equal the pictures alone (to their 10 printed digits)" \
	awk 'NR == FNR { a[FNR] = $1; n = FNR; next }
	     { d = a[FNR] - $1; if (d < 0) d = -d; if (d > 1e-9 * ($1 < 0 ? -$1 : $1)) bad = 1 }
	     END { exit bad || FNR != n }' "$TMP/od" "$TMP/alone1"
# mixed sizes: lines still work (weights rebuilt), a matrix is refused
"$BIN/mksens" -r 64 builtin:cosine >"$TMP/small.hdr"
out=$("$BIN/psens" -q -s builtin:cosine "$1" "$TMP/small.hdr" "$2" 2>"$TMP/err")
check "lines: mixed sizes give three results in order" \
	test "$(printf '%s\n' "$out" | cut -d: -f1 | tr '\n' ' ')" = "$1 $TMP/small.hdr $2 "
"$BIN/psens" -q -oa -s builtin:cosine "$1" "$TMP/small.hdr" "$2" >"$TMP/mixed" 2>"$TMP/err"
check "matrix of mixed sizes: exit 1" test $? = 1
check "matrix of mixed sizes: no matrix on stdout" test ! -s "$TMP/mixed"
check "matrix of mixed sizes: the error names the file and both sizes" \
	grep -q "$TMP/small.hdr: picture is 64 x 64, the batch's weights are for 256 x 256" "$TMP/err"
"$BIN/psens" -n 0 -s builtin:cosine "$1" >/dev/null 2>&1
check "-n 0 is bad usage (2)" test $? = 2
done_testing
