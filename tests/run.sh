#!/bin/sh
# SPDX-License-Identifier: ISC
# Run every test program and script given on the command line, read their TAP
# output (cmocka with CMOCKA_MESSAGE_OUTPUT=TAP, system scripts through
# tests/system/lib.sh) and end with one line: "check: N passed, N failed, N skipped".
# A program that exits 77 is skipped whole (its first output line says why).
# Output of each test goes to $LOGDIR/<name>.log; failures are printed in full.
LOGDIR=${LOGDIR:-${BUILD:-build}/test-logs}
mkdir -p "$LOGDIR"
pass=0; fail=0; skip=0; failed_files=""
for t in "$@"; do
	name=$(basename "$t")
	log="$LOGDIR/$name.log"
	t0=$(date +%s)
	case "$t" in
	*.sh) CMOCKA_MESSAGE_OUTPUT=TAP sh "$t" >"$log" 2>&1 ;;
	*)    CMOCKA_MESSAGE_OUTPUT=TAP "$t" >"$log" 2>&1 ;;
	esac
	rc=$?
	secs=$(($(date +%s) - t0))
	p=$(grep -c '^ok ' "$log")
	s=$(grep -c '^\(not \)\{0,1\}ok [0-9]* *#* *# SKIP' "$log")
	f=$(grep '^not ok ' "$log" | grep -vc '# SKIP')
	p=$((p - $(grep -c '^ok [0-9]* *#* *# SKIP' "$log")))
	if [ "$rc" = 77 ]; then
		why=$(head -n 1 "$log")
		echo "SKIP $name: $why"
		skip=$((skip + 1))
		continue
	fi
	if [ "$rc" != 0 ] && [ "$f" = 0 ]; then
		f=1   # crashed or failed outside a test case
	fi
	pass=$((pass + p)); fail=$((fail + f)); skip=$((skip + s))
	if [ "$f" != 0 ]; then
		echo "FAIL $name ($p passed, $f failed, $s skipped, exit $rc, ${secs} s):"
		sed 's/^/    /' "$log"
		failed_files="$failed_files $name"
	else
		echo "ok   $name ($p passed, $s skipped, ${secs} s)"
	fi
	grep '# SKIP' "$log" | sed "s/^/     $name: /"
done
[ -n "$failed_files" ] && echo "failed:$failed_files"
echo "check: $pass passed, $fail failed, $skip skipped"
[ "$fail" = 0 ]
