#!/bin/sh
# SPDX-License-Identifier: ISC
# psfilter and psens -f: an ideal V(lambda) filter (the CIE table itself) gives
# psens's defaults to 6 digits, and psens -f agrees with -R -G -B.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psfilter" ] || skip_all "psfilter not built"
awk '!/^#/ && NF { print $1, $2 }' sim/data/cie/cie_photopic_V_1nm.txt > "$TMP/v.txt"
out=$("$BIN/psfilter" "$TMP/v.txt")
first=$(printf '%s\n' "$out" | head -n 1)
check "V(lambda) gives the defaults: $first" test "$first" = "-R 0.265074 -G 0.670115 -B 0.064811"
check "f1' of V(lambda) is 0" sh -c "printf '%s\n' \"\$1\" | grep -q \"f1' .*: 0.00 %\"" sh "$out"
check "all 13 illuminants listed" test "$(printf '%s\n' "$out" | grep -cE '^  (A|D65|FL[0-9]+|HP[1-5]|LED-B[34]) ')" = 13
# a filter shifted 20 nm, in percent
awk '!/^#/ && NF { print $1 + 20, 100 * $2 }' sim/data/cie/cie_photopic_V_1nm.txt > "$TMP/v20.txt"
line=$("$BIN/psfilter" "$TMP/v20.txt" | head -n 1)
pic=config/example/ofb/img/day_0318_sensor_256.hdr
a=$("$BIN/psens" -q -s builtin:cosine -f "$TMP/v20.txt" "$pic" | sed 's/.*Response: //')
# shellcheck disable=SC2086
b=$("$BIN/psens" -q -s builtin:cosine $line "$pic" | sed 's/.*Response: //')
check "psens -f equals psens $line ($a vs $b, to the 6 printed digits)" \
	awk -v a="$a" -v b="$b" 'BEGIN { d = (a - b) / b; if (d < 0) d = -d; exit !(d < 2e-6) }'
# errors name file and line
printf '400 1\n390 1\n' > "$TMP/bad.txt"
"$BIN/psfilter" "$TMP/bad.txt" 2>"$TMP/err" && not_ok "unsorted filter accepted" || \
	check "unsorted filter: $(cat "$TMP/err")" grep -q "bad.txt:2: wavelength 390 nm comes after 400 nm" "$TMP/err"
done_testing
