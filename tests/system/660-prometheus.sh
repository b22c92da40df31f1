#!/bin/sh
# SPDX-License-Identifier: ISC
# [prometheus] textfile: psensd on the loopback room (real time, one step a
# minute, so status and the file see the same step) writes the point model
# in the text exposition format for node-exporter's textfile collector.
# Checked: the file appears and is rewritten every interval (atomically:
# no temporary file left beside it), every series parses (# HELP and
# # TYPE before each family, label zone), each value equals the one
# psensctl status gives (the levels in %, a binary 0/1, a multi-state one
# series per state with 1 on the state status names), Prometheus' own
# checker (promtool check metrics, Debian's prometheus package) finds no
# problem; a [prometheus] without textfile is refused with its line, and
# an unwritable path is logged while control goes on.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
conf() {   # conf PROM: the example with [prometheus] textfile = PROM
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; /^faults = /d" \
		config/psensd.conf > "$TMP/psensd.conf"
	printf '\n[prometheus]\ntextfile = %s\ninterval = 1\n' "$1" >> "$TMP/psensd.conf"
}
conf "$TMP/psensd.prom"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 ctl ping > /dev/null
check "the textfile appears" wait_for 5 test -s "$TMP/psensd.prom"
m1=$(stat -c %y "$TMP/psensd.prom" 2>/dev/null)
sleep 2.2
m2=$(stat -c %y "$TMP/psensd.prom" 2>/dev/null)
check "it is rewritten every interval ($m1, $m2)" test "$m1" != "$m2"
check "no temporary file is left beside it" sh -c "! ls $TMP/psensd.prom.* 2> /dev/null | grep -q ."
ctl -j status > "$TMP/status.json"
cp "$TMP/psensd.prom" "$TMP/snap.prom"
/usr/bin/python3 - "$TMP/status.json" "$TMP/snap.prom" > "$TMP/cmp.out" <<'EOP'
import json, re, sys
status = json.load(open(sys.argv[1]))
text = open(sys.argv[2]).read()
problems, seen, helped, typed = [], {}, set(), set()
for line in text.splitlines():
    if line.startswith('# HELP '):
        helped.add(line.split()[2]); continue
    if line.startswith('# TYPE '):
        typed.add(line.split()[2]); continue
    m = re.fullmatch(r'(psensd_[a-z_]+)\{zone="([^"]*)"(?:,state="([^"]*)")?\} (\S+)', line)
    if not m:
        problems.append('unparsed: ' + line); continue
    name, zone, state, value = m.groups()
    if name not in helped or name not in typed:
        problems.append('no HELP/TYPE before ' + name)
    key, value = name[len('psensd_'):], float(value)
    if key.endswith('_seconds'):   # a point in hours, in Prometheus' base unit
        key, value = key[:-len('_seconds')] + '_h', value / 3600
    seen[(key, zone, state)] = value
n = 0
for z in status['zones']:
    for key, v in z['points'].items():
        if isinstance(v, str):   # a multi-state point: 1 on its state
            got = seen.get((key, z['name'], v))
            want = 1.0
        else:
            got = seen.get((key, z['name'], None))
            want = None if v is None else float(v)
        if want is None:
            if got is not None:
                problems.append('%s %s: null in status, %s in the file' % (z['name'], key, got))
            continue
        if key in ('output_h', 'energy_kwh'):   # they grow between the two reads
            if got is None or not (got >= 0 and abs(got - want) <= 1e-3 + 1e-3 * abs(want)):
                problems.append('%s %s: status %s, file %s' % (z['name'], key, want, got))
        elif got is None or abs(got - want) > 1e-9 * max(1.0, abs(want)):
            problems.append('%s %s: status %s, file %s' % (z['name'], key, want, got))
        n += 1
print(n, len(seen))
for p in problems:
    print('#', p)
sys.exit(1 if problems or n < 8 else 0)
EOP
rc=$?
while read -r l; do diag "$l"; done < "$TMP/cmp.out"
check "every point status gives is in the file with the same value ($(head -n 1 "$TMP/cmp.out"))" test "$rc" = 0
check "the light level series is the zone's (%)" grep -q '^psensd_level{zone="office"} [0-9.e+-]*$' "$TMP/snap.prom"
if command -v promtool > /dev/null; then
	promtool check metrics < "$TMP/snap.prom" > "$TMP/promtool.out" 2>&1
	rc=$?
	while read -r l; do diag "promtool: $l"; done < "$TMP/promtool.out"
	check "promtool check metrics: no problem" test "$rc" = 0 -a ! -s "$TMP/promtool.out"
else
	skip "promtool is not installed (Debian: prometheus)"
fi
kill "$PID"; wait "$PID" 2> /dev/null

# a directory that cannot be written: logged once, control goes on
conf "$TMP/no/such/dir/psensd.prom"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 > "$TMP/out2" 2> "$TMP/err2" &
PID=$!; track_pid $PID
wait_for 10 ctl ping > /dev/null
sleep 2.5
check "an unwritable textfile is logged once" test "$(grep -c "prometheus: $TMP/no/such/dir/psensd.prom" "$TMP/err2")" = 1
check "and psensd still answers" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
kill "$PID"; wait "$PID" 2> /dev/null

sed '/^textfile = /d' "$TMP/psensd.conf" > "$TMP/bad.conf"
"$BIN/psensd" -n -f "$TMP/bad.conf" > "$TMP/bad.out" 2>&1
check "a [prometheus] without textfile is refused with its line" grep -q "bad.conf:[0-9]*: \[prometheus\] needs 'textfile'" "$TMP/bad.out"
done_testing
