#!/bin/sh
# SPDX-License-Identifier: ISC
# psensctl export --zone names a zone the log holds: a misspelled one is an
# error naming the zones there are (exit 1, nothing on standard output), not
# a CSV header and success that reads as "no samples".
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] && [ -x "$BIN/psensctl" ] || skip_all "not built"
example_results
B=$(cd "$BIN" && pwd); cd "$TMP" || exit 1
{ psensd_section 600
  printf '[device a]\ndriver = loopback\n[device b]\ndriver = loopback\n'
  printf '[zone office]\ndevice = a\n[zone hall]\ndevice = b\n'; } > p.conf
"$B/psensd" -f p.conf -s > day.out 2>&1; rc=$?
check "a simulated day of two zones runs (exit $rc)" test "$rc" = 0
# 06:00 to 20:00 at 600 s: 84 steps, each logging one sample a zone
"$B/psensctl" -d state/psensd.db export --zone office > office.csv 2> office.err; rc=$?
check "the zone office exports its 84 samples and a header (exit $rc, $(wc -l < office.csv) lines)" \
	test "$rc" = 0 -a "$(wc -l < office.csv)" = 85
"$B/psensctl" -d state/psensd.db export --zone ofice > typo.csv 2> typo.err; rc=$?
diag "$(cat typo.err)"
check "a misspelled zone exits 1 ($rc)" test "$rc" = 1
check "with nothing on standard output ($(wc -c < typo.csv) bytes)" test ! -s typo.csv
check "naming the zone asked for and the zones logged" \
	grep -q "no zone 'ofice' in .*psensd.db: its zones are hall, office" typo.err
done_testing
