#!/bin/sh
# SPDX-License-Identifier: ISC
# Commissioning psvirt's virtual gear with psensd's own tools: four gear
# without short addresses (--dali-unaddressed, two zones of two) behind the
# DALInet; psensctl dali scan sees gear without a short address and none
# that answers; psensctl dali address finds all four by the random-address
# search and gives them 0 to 3; each short address then answers QUERY
# RANDOM ADDRESS (H, M, L, asked by a Foxtron host of our own,
# peers/foxclient.py) with the random address psensctl printed for it, and
# a scan lists the four; psensctl dali group puts short 3 in group 1 and
# its QUERY GROUPS 0-7 answers 0x02.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
make_results
S="$TMP/sock"
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" --dali-unaddressed --zones 2 --start 12:00
{ printf '[psensd]\nresults = ofb.results\ndatabase = psensd.db\nsocket = sock\nperiod = 1\n'
psvirt_devices
cat <<EOF
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point lamps]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
dim = lamps
sensor_gain = 0.5
min_level = 0.1
EOF
} > "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
ps=$!; track_pid $ps
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
fox() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "$@"; }
wait_for 10 ctl ping > /dev/null || not_ok "psensd did not start: $(cat "$TMP/err")"
ctl dali dali scan > "$TMP/scan1" 2>&1
check "scan before: no short address answers, gear without one: $(head -n 1 "$TMP/scan1")" \
	grep -q "0 short addresses answer; gear without a short address: yes" "$TMP/scan1"
ctl dali dali address > "$TMP/addr" 2>&1
diag "$(cat "$TMP/addr")"
check "address: the four gear found, four new short addresses" grep -q "4 ballasts found: 4 new short addresses" "$TMP/addr"
for s in 0 1 2 3; do
	want=$(awk -v s=$s '$1 ~ /^0x/ && $2 == s { print toupper(substr($1, 3)) }' "$TMP/addr")
	a=$(printf '%02X' $((s * 2 + 1)))
	got=$(fox "send 16 ${a}C2; send 16 ${a}C3; send 16 ${a}C4" | awk '{ printf "%s", $2 }')
	check "short $s answers with the random address psensctl found for it: $got = $want" test -n "$want" -a "$got" = "$want"
done
ctl dali dali scan > "$TMP/scan2" 2>&1
check "scan after: four short addresses, none without one" \
	grep -q "4 short addresses answer; gear without a short address: none" "$TMP/scan2"
ctl dali dali group 3 add 1 > "$TMP/group" 2>&1
check "group: $(head -n 1 "$TMP/group")" grep -q "short address 3 is in group 1" "$TMP/group"
check "short 3's QUERY GROUPS 0-7: 0x02 ($(fox 'send 16 07C0'))" test "$(fox 'send 16 07C0')" = "answer 02"
done_testing
