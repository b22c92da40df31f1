#!/bin/sh
# SPDX-License-Identifier: ISC
# The driver man pages list exactly the keys the drivers' option tables
# declare (psensd -L prints the tables): a key added to a table and not to
# its page, or documented and gone from the table, fails here.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -L > "$TMP/tables" || skip_all "psensd -L failed"

# keys PAGE HEADING: the keys of the .TP items under a .SH/.SS heading (the
# first word of .B, every other word of .BR), to the next heading
keys() {
	awk -v h="$2" '
		/^\.S[HS] / { sub(/^\.S[HS] /, ""); gsub(/"/, ""); in_sec = ($0 == h); next }
		!in_sec { next }
		/^\.TP/ { tp = 1; next }
		tp && /^\.B / { print $2 }
		tp && /^\.BR / { gsub(/"[^"]*"/, " "); for (i = 2; i <= NF; i++) print $i }
		{ tp = 0 }' "$1" | sort -u
}
# table DRIVER SCOPE: the keys psensd -L prints for a driver and scope
table() {
	awk -v d="$1" -v s="$2" '/^[^ ]/ { cur = $1; sub(/:$/, "", cur); next } cur == d && $1 == s { print $2 }' \
		"$TMP/tables" | sort -u
}
compare() {  # compare DRIVER SCOPE PAGE HEADING
	if grep -q "^$1 (not compiled in)" "$TMP/tables"; then
		skip "$1 not compiled in: its table is not in this build"
		return
	fi
	keys "$3" "$4" > "$TMP/page"
	table "$1" "$2" > "$TMP/table"
	if [ ! -s "$TMP/table" ] && [ ! -s "$TMP/page" ]; then
		not_ok "$1 $2 keys: neither the table nor $3 has any"
		return
	fi
	check "$1 $2 keys: $3 ($4) lists the table's $(wc -l < "$TMP/table")$(diff "$TMP/table" "$TMP/page" | sed -n 's/^</; missing:/p; s/^>/; not in the table:/p' | tr '\n' ' ')" \
		cmp -s "$TMP/table" "$TMP/page"
}
compare loopback device config/psensd.conf.5 "loopback device keys"
compare loopback point config/psensd.conf.5 "loopback point keys"
for d in modbus:drivers/psensd-modbus.5 dali_usb:drivers/psensd-dali_usb.7 gpio:drivers/psensd-gpio.7 \
         file:drivers/psensd-file.7; do
	compare "${d%%:*}" device "${d#*:}" "DEVICE KEYS"
	compare "${d%%:*}" point "${d#*:}" "POINT KEYS"
done
# every driver in the registry has its page checked above
check "every registered driver is compared: $(awk '/^[^ ]/ { sub(/:.*/, ""); print $1 }' "$TMP/tables" | tr '\n' ' ')" \
	test "$(awk '/^[^ ]/ { sub(/:.*/, ""); print $1 }' "$TMP/tables" | sort | tr '\n' ' ')" = "dali_usb file gpio loopback modbus "
# the extraction itself, on a page whose keys are known
printf '.SH DEVICE KEYS\n.TP\n.BR a ", " b\n.TP\n.B c\nc is this.\n.SH POINT KEYS\n.TP\n.B d\n' > "$TMP/t.7"
check "the page parser reads .B and .BR items: $(keys "$TMP/t.7" "DEVICE KEYS" | tr '\n' ' ')" \
	test "$(keys "$TMP/t.7" "DEVICE KEYS" | tr '\n' ' ')" = "a b c "
done_testing
