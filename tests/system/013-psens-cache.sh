#!/bin/sh
# SPDX-License-Identifier: ISC
# psens's weight cache (the directory psscene uses): a cold run stores the
# map, a warm run reads it and prints the same numbers; -N runs uncached; a
# corrupted entry is rebuilt with a warning naming it; a read-only cache
# directory works uncached with one warning for the whole run.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] || skip_all "psens not built"
I=config/example/ofb/img
SEN=config/example/ofb/sensors/cosine.sen
C="$TMP/cache"
cold=$("$BIN/psens" -q -j -C "$C" -s "$SEN" $I/day_0318_sensor_256.hdr $I/elec_sensor_256.hdr)
n=$(find "$C/blobs" -type f ! -name .lock | wc -l)
check "cold: one map stored ($n)" test "$n" = 1
warm=$("$BIN/psens" -j -C "$C" -s "$SEN" $I/day_0318_sensor_256.hdr $I/elec_sensor_256.hdr 2>"$TMP/err")
check "warm: the same output" test "$warm" = "$cold"
check "warm: no warning" test ! -s "$TMP/err"
none=$("$BIN/psens" -q -j -N -s "$SEN" $I/day_0318_sensor_256.hdr $I/elec_sensor_256.hdr)
check "-N: the same output" test "$none" = "$cold"
f=$(find "$C/blobs" -type f ! -name .lock)
printf 'X' | dd of="$f" bs=1 seek=4000 conv=notrunc 2>/dev/null
again=$("$BIN/psens" -j -C "$C" -s "$SEN" $I/day_0318_sensor_256.hdr $I/elec_sensor_256.hdr 2>"$TMP/err")
check "corrupt entry: the same output" test "$again" = "$cold"
check "corrupt entry: a warning naming it" grep -q "$f: checksum mismatch" "$TMP/err"
check "corrupt entry: rebuilt in place" test -f "$f"
# read-only: as nobody when root (root writes anywhere), else chmod
RO="$TMP/ro"
mkdir -p "$RO" && chmod 755 "$TMP" && chmod 555 "$RO"
# nobody must reach the program and its inputs: a checkout may sit in a
# directory only root can enter (mktemp -d makes them 700), so copy them
P="$TMP/ro-run"
mkdir -p "$P" && cp "$BIN/psens" "$SEN" $I/day_0318_sensor_256.hdr $I/elec_sensor_256.hdr \
	$I/day_0318_task_256.hdr "$P/" && chmod -R a+rX "$P"
if [ "$(id -u)" = 0 ]; then
	if command -v setpriv >/dev/null; then
		run() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
	else
		run() { return 77; }
	fi
else
	run() { "$@"; }
fi
ro=$(cd "$P" && run ./psens -j -C "$RO" -s cosine.sen day_0318_sensor_256.hdr elec_sensor_256.hdr \
	day_0318_task_256.hdr 2>"$TMP/err")
rc=$?
if [ $rc = 77 ]; then
	skip "read-only cache: no setpriv to drop root"
else
	check "read-only cache: exit 0" test $rc = 0
	check "read-only cache: the same numbers" \
		test "$(printf '%s\n' "$ro" | head -n 2 | sed 's/"picture": "[^"]*"//')" = \
		"$(printf '%s\n' "$cold" | sed 's/"picture": "[^"]*"//')"
	check "read-only cache: exactly one warning" test "$(grep -c 'not cached' "$TMP/err")" = 1
	check "read-only cache: it names the directory" grep -q "$RO/blobs" "$TMP/err"
	check "read-only cache: nothing written" test -z "$(ls -A "$RO")"
fi
done_testing
