#!/bin/sh
# SPDX-License-Identifier: ISC
# Messages that say what is wrong: a bad option names that option and its
# range only; an out-of-range TCP port is refused, not taken modulo 65536; a
# write error names the file asked for, not the copy written beside it; a
# misspelt builtin lists the builtins; a missing picture is named as missing;
# a misspelt psensctl command is bad usage (exit 2) before psensd is asked;
# an output name that is not .png is refused by the PNG writer; a log that
# cannot be read prints its error alone, no header on standard output.
. "$(dirname "$0")/lib.sh"
pic=tests/data/picture/day_0318_sensor_256.hdr

# run PROGRAM ARGS...: $rc, $TMP/out, $TMP/err (at most 5 s: nothing listens)
run() { timeout 5 "$@" > "$TMP/out" 2> "$TMP/err"; rc=$?; }

run "$BIN/psvirt" --tcp 127.0.0.1:99999
check "psvirt --tcp :99999: exit 2 ($rc), the port refused: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q \"port '99999' is not 0 to 65535\" '$TMP/err'"
run "$BIN/psvirt" --tcp 127.0.0.1:0 --speed -1
check "psvirt --speed -1: exit 2 ($rc), names --speed: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q -- '--speed must be >= 0' '$TMP/err'"
check "psvirt --speed -1: no other option's range, no usage" \
	sh -c "! grep -q -e '--unit' -e '--late-ms' -e '^usage' '$TMP/err'"
run "$BIN/psvirt" --tcp 127.0.0.1:0 --unit 300
check "psvirt --unit 300: exit 2 ($rc), names --unit only: $(cat "$TMP/err")" \
	sh -c "[ $rc = 2 ] && [ \$(wc -l < '$TMP/err') = 1 ] && grep -q -- '--unit must be 1 to 247' '$TMP/err'"

run "$BIN/pssynwea" -a 200
check "pssynwea -a 200: exit 2 ($rc), latitude's range: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q 'latitude 200 is not -90 to 90' '$TMP/err' && [ ! -s '$TMP/out' ]"
run "$BIN/pssynwea" -z 20
check "pssynwea -z 20: exit 2 ($rc), the time zone's range: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q 'time zone 20 is not -14 to 14' '$TMP/err'"

run "$BIN/pspng" -q -o "$TMP/no/such/dir/x.png" "$pic"
check "pspng into a missing directory: exit 1 ($rc), names x.png: $(cat "$TMP/err")" \
	sh -c "[ $rc = 1 ] && grep -q 'dir/x.png: No such file' '$TMP/err' && ! grep -q 'png.tmp' '$TMP/err'"
run "$BIN/pspng" -q -o "$TMP/x.jpg" "$pic"
check "pspng -o x.jpg: exit 2 ($rc), refused, nothing written: $(cat "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q 'x.jpg.*does not end in .png' '$TMP/err' && [ ! -e '$TMP/x.jpg' ]"
run "$BIN/pspng" -q -o "$TMP/x.PNG" "$pic"
check "pspng -o x.PNG: written ($rc)" sh -c "[ $rc = 0 ] && [ -s '$TMP/x.PNG' ]"
run "$BIN/pspng" -q -o "$TMP/x.png"
check "pspng without a picture: exit 2 ($rc), says so: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q '^pspng: no picture' '$TMP/err'"

run "$BIN/psens" -q -N -s builtin:cosin "$pic"
check "psens -s builtin:cosin: exit 1 ($rc), lists the builtins: $(cat "$TMP/err")" \
	sh -c "[ $rc != 0 ] && grep -q 'builtin:cosine or builtin:uniform' '$TMP/err'"
run "$BIN/psens" -s builtin:cosine
check "psens without a picture: exit 2 ($rc), says so: $(head -n 1 "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q '^psens: no picture' '$TMP/err'"

run "$BIN/psensctl" -s "$TMP/nosuch.sock" statsu
check "psensctl statsu: exit 2 ($rc) as psensctl(1) says, names it: $(cat "$TMP/err")" \
	sh -c "[ $rc = 2 ] && grep -q \"'statsu' is not a command\" '$TMP/err'"
run "$BIN/psensctl" -s "$TMP/nosuch.sock" status
check "psensctl status with no psensd: still exit 1 ($rc), cannot reach" \
	sh -c "[ $rc = 1 ] && grep -q 'cannot reach' '$TMP/err'"
run "$BIN/psensctl" -d "$TMP/nosuch.db" log
check "psensctl -d nosuch.db log: exit 1 ($rc), nothing on standard output ($(cat "$TMP/out"))" \
	sh -c "[ $rc = 1 ] && [ ! -s '$TMP/out' ] && grep -q 'nosuch.db' '$TMP/err'"
run "$BIN/psensctl" -d "$TMP/nosuch.db" export --format csv
check "psensctl -d nosuch.db export: exit 1 ($rc), nothing on standard output" \
	sh -c "[ $rc = 1 ] && [ ! -s '$TMP/out' ]"
done_testing
