#!/bin/sh
# SPDX-License-Identifier: ISC
# pssynwea: the tests' synthetic year is its output (reproducible), the
# year reads as a weather file (pssky), every hour once, no light at night,
# and bad options are refused.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/pssynwea" ] || skip_all "pssynwea not built"
"$BIN/pssynwea" > "$TMP/sf.wea"
check "the tests' synthetic year is pssynwea's default output" cmp -s "$TMP/sf.wea" tests/data/weather/sf-synthetic.wea
check "8760 hours" test "$(tail -n +7 "$TMP/sf.wea" | wc -l)" = 8760
"$BIN/pssynwea" -s 2 > "$TMP/s2.wea"
check "another seed, another year" sh -c "! cmp -s '$TMP/sf.wea' '$TMP/s2.wea'"
check "pssky reads it" sh -c "'$BIN/pssky' -m 1 '$TMP/sf.wea' > '$TMP/sky.mtx'"
check "no light at midnight" sh -c "! awk 'NR > 6 && \$3 == 0.5 && (\$4 > 0 || \$5 > 0)' '$TMP/sf.wea' | grep -q ."
# -C: every day clear, so no hour's beam is cut: noon beam at its clear value every day
"$BIN/pssynwea" -C > "$TMP/c.wea"
check "-C: the beam at noon is the clear sky's every day (over 600 W/m2)" \
	sh -c "! awk 'NR > 6 && \$3 == 12.5 && \$4 < 600' '$TMP/c.wea' | grep -q ."
"$BIN/pssynwea" -a 95 > /dev/null 2>&1
check "a latitude of 95 is refused" test $? = 2
"$BIN/pssynwea" -s x > /dev/null 2> "$TMP/err"
check "a bad number is named" grep -q "'x' is not a number" "$TMP/err"
# the file says it is synthetic whatever the site is called
check "-n Oakland writes place Oakland_synthetic" test "$("$BIN/pssynwea" -n Oakland | head -n 1)" = "place Oakland_synthetic"
check "-n my_synthetic_site is kept" test "$("$BIN/pssynwea" -n my_synthetic_site | head -n 1)" = "place my_synthetic_site"
done_testing
