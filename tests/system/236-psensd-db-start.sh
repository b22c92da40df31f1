#!/bin/sh
# SPDX-License-Identifier: ISC
# A start on a database psensd cannot use, over Modbus TCP against psvirt:
# the light is left at 10 % (as a daemon killed at noon would leave it),
# then psensd starts on a truncated file, a garbage header, a text file, a
# directory and another application's SQLite file.  Each start is refused
# (exit 1) with the real cause named, and psvirt's dim register shows the
# light at the zone's safe level (100 %) afterwards; the other
# application's file is not written.  A file with garbage in its last pages
# opens: psensd runs with its log degraded ("corrupt"), the control goes on,
# and SIGTERM still leaves the light at the safe level.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need sqlite3
make_results
port=$(free_port)
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
	--start 12:00 -D gain=0.5 -D lag_tau=0 -D min_level=0.1 -D fade_rate=0 > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
track_pid $!
wait_for 10 test -s "$TMP/ready"
{ device_tcp "$port" timeout=0.5 retries=1; points; } > "$TMP/io.conf"
conf() {  # conf DB: psensd on psvirt, safe level 100 %
	{ cat <<EOC
[psensd]
results = $TMP/ofb.results
database = $1
socket = $TMP/sock
period = 1
safe_level = 1.0
EOC
	cat "$TMP/io.conf"
	cat <<EOC
[zone office]
sensor = sensor
dim = dim
target_lux = 500
sensor_gain = 0.5
min_level = 0.1
EOC
	} > "$TMP/psensd.conf"
}
dim() { "$MBDRIVE" "$TMP/io.conf" read dim | sed -n 's/^dim = \([0-9.]*\).*/\1/p'; }
# a psensd database of a few pages, made by psensd
conf "$TMP/good.db"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 -x 60 > /dev/null 2>&1 &
pd=$!; track_pid $pd
wait_for 20 sh -c "[ \$(sqlite3 '$TMP/good.db' 'SELECT count(*) FROM samples' 2>/dev/null || echo 0) -ge 40 ]"
kill -TERM $pd; wait $pd
sqlite3 "$TMP/good.db" "PRAGMA wal_checkpoint(TRUNCATE)" > /dev/null
pages=$(sqlite3 "$TMP/good.db" "PRAGMA page_count")
diag "a psensd database of $pages pages of 4096 bytes"
check "psensd marks its file (application_id 0x50534E44)" test "$(sqlite3 "$TMP/good.db" "PRAGMA application_id")" = 1347636804

# refused KIND FILE CAUSE: dim at 10 %, a start on FILE refused naming CAUSE, dim at 100 %
refused() {
	"$MBDRIVE" "$TMP/io.conf" write dim 0.1 > /dev/null 2>&1
	before=$(dim)
	conf "$2"
	timeout 20 "$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err"
	rc=$?
	check "$1: the start is refused (exit $rc)" test "$rc" = 1
	check "$1: the cause: $(grep -o "$3.*" "$TMP/err" | head -1 | cut -c1-90)" grep -q "$3" "$TMP/err"
	check "$1: every zone said at the safe level" grep -q "zone office: the log cannot be opened: lights at the safe level 100 %" "$TMP/err"
	after=$(dim)
	# the register holds 12 bits (raw_max 4095): 0.1 reads 0.1001
	if near "$before" 0.1 0.001 && near "$after" 1 0.001; then ok "$1: psvirt's light $before -> $after (the safe level)"
	else not_ok "$1: psvirt's light $before -> $after, not 0.1 -> 1 (the safe level)"; fi
}
head -c 8192 "$TMP/good.db" > "$TMP/truncated.db"
refused "truncated to 2 pages" "$TMP/truncated.db" "corrupt (database disk image is malformed)"
check "truncated: the message gives the commands" grep -q "mv $TMP/truncated.db $TMP/truncated.db.corrupt" "$TMP/err"
cp "$TMP/good.db" "$TMP/header.db"
dd if=/dev/urandom of="$TMP/header.db" bs=100 count=1 conv=notrunc 2>/dev/null
refused "garbage header" "$TMP/header.db" "corrupt (file is not a database)"
echo "t,level" > "$TMP/text.db"
refused "a text file" "$TMP/text.db" "corrupt (file is not a database)"
mkdir "$TMP/dir.db"
refused "a directory" "$TMP/dir.db" "is a directory, not a database file"
sqlite3 "$TMP/other.db" "CREATE TABLE contacts(name TEXT, phone TEXT); INSERT INTO contacts VALUES('a', '1');"
sum0=$(sha256sum < "$TMP/other.db")
refused "another application's SQLite file" "$TMP/other.db" "not a psensd database (its tables: contacts)"
check "its file is not written" test "$(sha256sum < "$TMP/other.db")" = "$sum0"
check "and no lock file is made beside it" test ! -e "$TMP/other.db.lock"
sqlite3 "$TMP/app.db" "CREATE TABLE samples(t REAL); PRAGMA application_id = 42;"
refused "a file with another application_id" "$TMP/app.db" "not a psensd database (application_id 42)"

# garbage in the last pages: it opens; writes fail, control goes on
cp "$TMP/good.db" "$TMP/tail.db"
dd if=/dev/urandom of="$TMP/tail.db" bs=4096 seek=$((pages - 2)) count=2 conv=notrunc 2>/dev/null
"$MBDRIVE" "$TMP/io.conf" write dim 0.1 > /dev/null 2>&1
conf "$TMP/tail.db"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 -x 60 > "$TMP/out" 2> "$TMP/err" &
pd=$!; track_pid $pd
wait_for 20 "$BIN/psensctl" -s "$TMP/sock" ping > /dev/null
wait_for 20 sh -c "\"$BIN/psensctl\" -s '$TMP/sock' -j status | grep -q '\"state\":\"degraded\"'"
st=$("$BIN/psensctl" -s "$TMP/sock" -j status)
check "garbage in the last pages: the log is degraded, the cause is corruption" \
	sh -c "echo '$st' | grep -q '\"cause\":\"corrupt (database disk image is malformed)\"'"
steps0=$(echo "$st" | grep -o '"steps":[0-9]*' | cut -d: -f2)
wait_for 20 sh -c "[ \$(\"$BIN/psensctl\" -s '$TMP/sock' -j status | grep -o '\"steps\":[0-9]*' | cut -d: -f2) -ge $((steps0 + 3)) ]"
steps1=$("$BIN/psensctl" -s "$TMP/sock" -j status | grep -o '"steps":[0-9]*' | cut -d: -f2)
check "garbage in the last pages: the control steps on ($steps0 -> $steps1)" test "$steps1" -ge $((steps0 + 3))
check "one LOG_ERR line names the corruption" test "$(grep -c 'the sample log cannot be written: corrupt' "$TMP/err")" = 1
kill -TERM $pd; wait $pd
check "SIGTERM: the light at the safe level ($(dim))" near "$(dim)" 1 0.001
check "SIGTERM: the samples that could not be written are counted as lost" grep -q "samples held in memory could not be written before the log closed" "$TMP/err"
done_testing
