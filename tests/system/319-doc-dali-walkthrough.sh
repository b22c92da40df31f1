#!/bin/sh
# SPDX-License-Identifier: ISC
# The DALI site dry run of doc/site.md as written, on a fresh copy of the
# tree (no results computed yet, a ready file left by an earlier run): psvirt
# serves config/example/dali-virtual.conf's room as a Modbus module and a
# DALInet, psensd dims the two virtual ballasts through its DALI driver.
# Checked: psvirt says where its DALInet listens; psensd starts only once
# psvirt is ready and runs without a fault; the gear were dimmed (samples
# below full output) and psvirt counted the DALI frames.  Then the section's
# second block, commissioning unaddressed gear with psensctl dali, as
# written: the three gear found and listed.  The ports are free
# ones instead of 1502 and 1523 (in the copied configuration too) and psensd
# runs 8 s of the document's 86.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
BINABS=$(cd "$BIN" && pwd)
mkdir -p "$TMP/top/config" "$TMP/top/build"
cp -R config/example "$TMP/top/config/"
ln -s "$BINABS" "$TMP/top/build/bin"
mb=$(free_port)
dali=$(free_port)
awk '/^## A DALI site dry run/ { s = 1; next } /^## / { s = 0 }
     s && /^```/ { if (b) exit; b = 1; next }
     s && b && /^\$ / { c = 1; sub(/^\$ /, "") } s && b && c { print; c = /\\$/ }' doc/site.md |
	sed -e "s/1502/$mb/g" -e "s/1523/$dali/g" -e 's/^timeout 86 /timeout 8 /' -e 's/; kill %1; wait %1$/; kill $!; wait $!/' \
	-e '/^timeout 8 /q' > "$TMP/dali.sh"
sed -i -e "s/^port = 1502/port = $mb/" -e "s/127.0.0.1:1523/127.0.0.1:$dali/" "$TMP/top/config/example/dali-virtual.conf"
diag "$(cat "$TMP/dali.sh")"
check "the walk-through removes an earlier ready file" grep -q '^rm -f build/psvirt-dali.ready$' "$TMP/dali.sh"
check "... and waits for psvirt's" grep -q '^until \[ -s build/psvirt-dali.ready \]' "$TMP/dali.sh"
check "... and ends psensd's run with a timeout" grep -q '^timeout 8 build/bin/psensd -f config/example/dali-virtual.conf' "$TMP/dali.sh"
echo 1 > "$TMP/top/build/psvirt-dali.ready"   # an earlier run's
(cd "$TMP/top" && setsid sh -c '. "$1"' sh "$TMP/dali.sh") > "$TMP/out" 2> "$TMP/err" &
W=$!
i=0; while kill -0 $W 2>/dev/null && [ $i -lt 900 ]; do sleep 0.1; i=$((i + 1)); done
kill -TERM -- -$W 2>/dev/null
diag "$(head -n 12 "$TMP/err")"
check "psvirt says where its DALInet listens" grep -q "^psvirt: DALI bus (Foxtron DALInet) on port $dali\$" "$TMP/out"
check "psensd ran" grep -q "controlling 1 zone(s) from config/example/dali-virtual.conf" "$TMP/err"
check "no connection refused and no fault: $(grep -m 1 -i 'fault\|refused' "$TMP/err")" \
	sh -c "! grep -qi 'fault:\|refused' '$TMP/err'"
n=$(sqlite3 "$TMP/top/build/dali-virtual.db" "select count(*) from samples where output < 0.99")
check "the ballasts were dimmed over DALI ($n samples below full output)" test "${n:-0}" -gt 10
check "psvirt counted the DALI frames: $(grep 'DALI frames' "$TMP/out")" grep -Eq '^psvirt: [1-9][0-9]* DALI frames$' "$TMP/out"

# the second block: commissioning the unaddressed gear, run with bash (its
# kill %2 needs a job table); psvirt's and psensd's ports as above
command -v bash > /dev/null || { done_testing; exit; }
awk '/^## A DALI site dry run/ { s = 1; next } /^## / { s = 0 }
     s && /^```/ { n++; next }
     s && n == 3 && /^\$ / { c = 1; sub(/^\$ /, "") } s && n == 3 && c { print; c = /\\$/ }' doc/site.md |
	sed -e "s/1502/$mb/g" -e "s/1523/$dali/g" > "$TMP/commission.sh"
diag "$(cat "$TMP/commission.sh")"
check "the commissioning block starts psvirt with its gear unaddressed" grep -q -- '--dali-unaddressed' "$TMP/commission.sh"
(cd "$TMP/top" && timeout 120 setsid bash "$TMP/commission.sh") > "$TMP/out2" 2> "$TMP/err2"
diag "$(cat "$TMP/out2")"
check "psensctl dali address found the three gear" \
	grep -q "^dali address done in .*: 3 ballasts found: 3 new short addresses" "$TMP/out2"
check "psensctl dali scan lists them at short addresses 0 to 2" \
	grep -q "^dali scan done in .*: 3 short addresses answer; gear without a short address: none" "$TMP/out2"
check "psvirt ended with its summary" grep -Eq '^psvirt: [1-9][0-9]* DALI frames$' "$TMP/out2"
done_testing
