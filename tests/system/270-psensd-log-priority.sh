#!/bin/sh
# SPDX-License-Identifier: ISC
# Log priorities: under systemd psensd's stderr is the journal (JOURNAL_STREAM
# names its device and inode), and each line carries sd-daemon(3)'s "<N>"
# prefix, so `journalctl -p err` finds a refused configuration or lights that
# cannot reach the safe level, while faults the daemon handles are warnings
# and the rest information.  In a terminal the lines are as they were.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
stream() { stat -c '%d:%i' "$1"; }   # what systemd puts in JOURNAL_STREAM

# a refused configuration: every error at LOG_ERR (3)
printf '[psensd]\nresults = state/ofb.results\nperiod = 0\n[device room]\ndriver = loopback\n[zone z]\ndevice = room\nalgorithm = nosuch\n' > "$TMP/bad.conf"
: > "$TMP/bad.err"
JOURNAL_STREAM=$(stream "$TMP/bad.err") "$BIN/psensd" -f "$TMP/bad.conf" -n 2>> "$TMP/bad.err" > /dev/null
check "refused: every line at priority 3: $(head -n 1 "$TMP/bad.err")" \
	sh -c "[ \$(grep -c . '$TMP/bad.err') -ge 2 ] && ! grep -qv '^<3>' '$TMP/bad.err'"
check "refused: file and line kept" grep -q "^<3>$TMP/bad.conf:3: period" "$TMP/bad.err"
# the same in a terminal (stderr is not the stream systemd named)
JOURNAL_STREAM=$(stream "$TMP/bad.conf") "$BIN/psensd" -f "$TMP/bad.conf" -n 2> "$TMP/tty.err" > /dev/null
check "in a terminal: the program's name, no priority: $(head -n 1 "$TMP/tty.err")" \
	sh -c "grep -q '^psensd: $TMP/bad.conf:3: period' '$TMP/tty.err' && ! grep -q '^<' '$TMP/tty.err'"

# a simulated day on the loopback room: the fault is a warning (4), the rest
# information (6)
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/day.db|; s|^end = .*|end = 12:30|" \
	config/psensd.conf > "$TMP/day.conf"
: > "$TMP/day.err"
JOURNAL_STREAM=$(stream "$TMP/day.err") "$BIN/psensd" -f "$TMP/day.conf" -s 2>> "$TMP/day.err" > /dev/null
check "a handled fault at priority 4" grep -q "^<4>zone office: [0-9-]* *12:00 fault: sensor reads 0.000 V" "$TMP/day.err"
check "its clearing at priority 6" grep -q "^<6>zone office: [0-9-]* *12:20 fault cleared" "$TMP/day.err"

# outputs that cannot be commanded even to the safe level (a Modbus module
# nobody answers for): priority 3, once
port=$(free_port)
cat > "$TMP/gone.conf" <<EOF
[psensd]
results = state/ofb.results
period = 60
[simulate]
start = 06:00
end = 06:10
[device io]
driver = modbus
host = 127.0.0.1
port = $port
timeout = 0.05
[point s]
device = io
role = sensor
table = input_register
address = 0
[point d]
device = io
role = dim
table = holding_register
address = 10
[zone z]
sensor = s
dim = d
EOF
: > "$TMP/gone.err"
JOURNAL_STREAM=$(stream "$TMP/gone.err") "$BIN/psensd" -f "$TMP/gone.conf" -s 2>> "$TMP/gone.err" > /dev/null
check "the safe level unreachable: priority 3: $(grep -m 1 'cannot reach' "$TMP/gone.err")" \
	grep -q "^<3>zone z: [0-9-]* *06:00 cannot reach the safe level: modbus io" "$TMP/gone.err"
check "said once, not every period" test "$(grep -c '^<3>zone z: [0-9-]* *[0-9:][0-9:]* cannot reach the safe level' "$TMP/gone.err")" = 1
check "and at shutdown, still at priority 3" grep -q "^<3>zone z: cannot reach the safe level" "$TMP/gone.err"
done_testing
