#!/bin/sh
# SPDX-License-Identifier: ISC
# pssky against Radiance's own gendaymtx test (every printed value), its
# output formats and options (-of -od -h -d -s -A -u -m -5 -O1), the same
# weather as an .epw, standard input, and bad input: file:line on stderr and
# nothing on standard output.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/pssky" ] || skip_all "pssky not built"
D=tests/data/gendaymtx
PSSKY=$(cd "$BIN" && pwd)/pssky
# values after the header, one a line
values() { awk 'body && NF { for (i = 1; i <= NF; i++) print $i } !NF { body = 1 }' "$1"; }
# doubles of a headerless -od file, one a line
doubles() { od -An -v -t f8 "$1" | awk '{ for (i = 1; i <= NF; i++) print $i }'; }

# the acceptance: the same command line as Radiance's test
(cd "$D" && "$PSSKY" -r 90 -m 1 -g .3 .2 .1 -c .9 .9 1.2 test.wea) > "$TMP/test.smx" 2>"$TMP/err"
check "pssky runs on test.wea" test -s "$TMP/test.smx"
for h in "LATLONG= 37.42000000 -122.05000000" NROWS=146 NCOLS=56 NCOMP=3 FORMAT=ascii; do
	check "header has $h" grep -qx "$h" "$TMP/test.smx"
done
values "$D/test.smx" > "$TMP/ref.txt"
values "$TMP/test.smx" > "$TMP/got.txt"
# the same text printed with %.3g, the reference's own precision (test_sky
# measures the distance of the unrounded values)
cmp_out=$(paste "$TMP/ref.txt" "$TMP/got.txt" | awk '
	{ n++; if ($1 == $2) m++ }
	END { printf "%d of %d values printed the same\n", m, n; exit !(m == n && n == 24528) }')
check "Radiance's test.smx: $cmp_out" test $? = 0
diag "$cmp_out"

# binary formats and no header
(cd "$D" && "$PSSKY" -od -h test.wea) > "$TMP/full.d"
check "-od -h: 146 x 56 x 3 doubles, no header" test "$(wc -c < "$TMP/full.d")" = $((146 * 56 * 24))
(cd "$D" && "$PSSKY" -of test.wea) > "$TMP/full.f"
check "-of: FORMAT=float and the byte order" sh -c "head -c 200 '$TMP/full.f' | grep -a -q '^FORMAT=float' && head -c 200 '$TMP/full.f' | grep -a -q '^BYTEORDER='"
# the sun alone plus the sky alone is the whole (-d drops the ground, -s keeps it)
(cd "$D" && "$PSSKY" -od -h -d test.wea) > "$TMP/sun.d"
(cd "$D" && "$PSSKY" -od -h -s test.wea) > "$TMP/sky.d"
doubles "$TMP/full.d" > "$TMP/full.txt"
doubles "$TMP/sun.d" > "$TMP/sun.txt"
doubles "$TMP/sky.d" > "$TMP/sky.txt"
check "-d + -s = the whole sky (to float precision)" sh -c "paste '$TMP/full.txt' '$TMP/sun.txt' '$TMP/sky.txt' | awk '{ d = \$1 - \$2 - \$3; if (d < 0) d = -d; if (d > 1e-6 * (\$1 < 0 ? -\$1 : \$1) + 1e-30) bad++ } END { exit bad > 0 }'"
check "-d: the ground is 0" sh -c "head -n $((56 * 3)) '$TMP/sun.txt' | awk '\$1 != 0 { bad++ } END { exit bad > 0 }'"
# -A: one column, the mean of the 56
(cd "$D" && "$PSSKY" -od -h -A test.wea) > "$TMP/avg.d"
doubles "$TMP/avg.d" > "$TMP/avg.txt"
check "-A: one column of 146 x 3" test "$(wc -l < "$TMP/avg.txt")" = 438
check "-A is the mean of the columns" sh -c "awk 'NR == FNR { a[NR - 1] = \$1; next } { k = FNR - 1; p = int(k / (56 * 3)); r = k % 3; s[p * 3 + r] += \$1 } END { for (i in a) { d = a[i] - s[i] / 56; if (d < 0) d = -d; if (d > 1e-9 * (a[i] < 0 ? -a[i] : a[i]) + 1e-12) bad++ } exit bad > 0 }' '$TMP/avg.txt' '$TMP/full.txt'"
check "-A writes NAVERAGED=56" sh -c "cd '$D' && '$PSSKY' -A test.wea | grep -qx NAVERAGED=56"
# -u: the 48 steps with the sun's disc above the horizon
check "-u keeps 48 of 56 steps" sh -c "cd '$D' && '$PSSKY' -u test.wea | grep -qx NCOLS=48"
for mf in 2 4 6; do
	n=$(cd "$D" && "$PSSKY" -m $mf -A test.wea | sed -n 's/^NROWS=//p')
	check "-m $mf: $n patches" test "$n" = $((144 * mf * mf + 2))
done
# -5: the sun whole in one patch a step
(cd "$D" && "$PSSKY" -od -h -d -5 0.533 test.wea) > "$TMP/five.d"
doubles "$TMP/five.d" > "$TMP/five.txt"
check "-5: at most one sun patch a step" sh -c "awk '{ k = NR - 1; if (k % 3 == 1 && \$1 > 0) n[int(k / 3) % 56]++ } END { for (c in n) if (n[c] > 1) bad++; exit bad > 0 || length(n) < 40 }' '$TMP/five.txt'"
# -O1: solar radiance is brighter in W/sr/m2 than the visible (efficacy above 179 lm/W)
check "-O1 differs from -O0" sh -c "cd '$D' && ! '$PSSKY' -O1 test.wea | cmp -s - '$TMP/test.smx'"

# the same weather as an EnergyPlus file (dew point 11 C, records ending on the hour)
awk 'NR == 1 { print "LOCATION,Mountain View,CA,USA,test,724945,37.42,-122.05,-8.0,12.0"
	print "DESIGN CONDITIONS,0"; print "TYPICAL/EXTREME PERIODS,0"; print "GROUND TEMPERATURES,0"
	print "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0"; print "COMMENTS 1,from Radiance test.wea"
	print "COMMENTS 2,"; print "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31" }
	NR > 6 { printf "1999,%d,%d,%d,60,?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9?9*9*9?9?9?9,10.0,11.0,80,101300,0,0,300,%g,%g,%g,999999,999999,999999,9999,180,2.0,5,5,16.0,77777,9,999999999,10,0.100,0,88,0.200,0.0,0.0\n", $1, $2, $3 + 0.5, $4 + $5, $4, $5 }' \
	"$D/test.wea" > "$TMP/test.epw"
"$PSSKY" -r 90 -m 1 -g .3 .2 .1 -c .9 .9 1.2 "$TMP/test.epw" > "$TMP/epw.smx"
values "$TMP/epw.smx" > "$TMP/epw.txt"
check "the .epw gives the same 24528 values" cmp -s "$TMP/got.txt" "$TMP/epw.txt"
(cd "$D" && "$PSSKY" -r 90 -m 1 -g .3 .2 .1 -c .9 .9 1.2 < test.wea) > "$TMP/stdin.smx"
values "$TMP/stdin.smx" > "$TMP/stdin.txt"
check "standard input gives the same values" cmp -s "$TMP/got.txt" "$TMP/stdin.txt"

# bad input: file:line, exit 1, nothing on standard output
bad() {   # bad NAME LINE-NUMBER REPLACEMENT EXPECTED
	awk -v n="$2" -v r="$3" 'NR == n { print r; next } { print }' "$D/test.wea" > "$TMP/$1.wea"
	"$PSSKY" "$TMP/$1.wea" > "$TMP/$1.out" 2> "$TMP/$1.err"
	rc=$?
	printf '%s\n' "$TMP/$1.wea:$2: $4" > "$TMP/$1.want"
	check "$1: exit 1, $(cat "$TMP/$1.err")" sh -c "test $rc = 1 && grep -qF -f '$TMP/$1.want' '$TMP/$1.err'"
	check "$1: nothing written" test ! -s "$TMP/$1.out"
}
bad nan 14 "3 21 12.5 nan 283" "direct 'nan' is not a finite number"
bad negative 15 "3 21 13.5 40 -305" "negative diffuse irradiance -305"
bad missing 16 "3 21 14.5 37" "4 fields, expected 5"
bad extra 16 "3 21 14.5 37 257 1" "6 fields, expected 5"
bad order 17 "3 21 13.0 29 189" "3/21 13 h does not come after 3/21 14.5 h (line 16)"
bad nosite 1 "place " "the header names no site"
bad feb30 17 "2 30 15.5 29 189" "day 30 is not in February (1 to 29)"
"$PSSKY" -m 0 "$D/test.wea" > "$TMP/m0.out" 2> "$TMP/m0.err"
rc=$?
check "-m 0: exit 2, $(cat "$TMP/m0.err")" test "$rc" = 2 -a ! -s "$TMP/m0.out"
"$PSSKY" -q "$D/test.wea" > /dev/null 2>&1
rc=$?
check "an unknown option exits 2" test "$rc" = 2
done_testing
