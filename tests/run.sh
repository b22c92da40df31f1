#!/bin/sh
# SPDX-License-Identifier: ISC
# Run every test program and script given on the command line, read their TAP
# output (cmocka with CMOCKA_MESSAGE_OUTPUT=TAP, system scripts through
# tests/system/lib.sh) and end with one line: "check: N passed, N failed, N skipped".
# A program that exits 77 is skipped whole (its first output line says why).
#
# Usage: tests/run.sh [-j N] TEST...
# -j N (or CHECK_JOBS=N) runs N tests at once; each test's report is printed
# whole when it ends, so the output of two tests never interleaves.  A script
# with a line "# check: alone" runs after the others, by itself (it measures
# rates or wall-clock time that a loaded machine would distort).  A script with
# "# check: long" starts first, so that the long tests do not end the run
# alone.  Each test is stopped after CHECK_TIMEOUT seconds (1800) and counted
# as failed.  Output of each test goes to $LOGDIR/<name>.log.
LOGDIR=${LOGDIR:-${BUILD:-build}/test-logs}
jobs=${CHECK_JOBS:-1}
if [ "${1:-}" = -j ]; then
	jobs=$2
	shift 2
fi
case "$jobs" in
''|*[!0-9]*|0) echo "tests/run.sh: -j wants a positive number of tests at once, not '$jobs'" >&2; exit 2 ;;
esac
mkdir -p "$LOGDIR"
here=$(cd "$(dirname "$0")" && pwd)
export LOGDIR

# one test: its log, its result line ($LOGDIR/<name>.res: passed failed
# skipped) and its report, printed under a lock so reports stay whole
if [ "${1:-}" = --one ]; then
	t=$2
	name=$(basename "$t")
	log="$LOGDIR/$name.log"
	report="$LOGDIR/$name.report"
	t0=$(date +%s)
	case "$t" in
	*.sh) CMOCKA_MESSAGE_OUTPUT=TAP timeout -k 10 "${CHECK_TIMEOUT:-1800}" sh "$t" >"$log" 2>&1 ;;
	*)    CMOCKA_MESSAGE_OUTPUT=TAP timeout -k 10 "${CHECK_TIMEOUT:-1800}" "$t" >"$log" 2>&1 ;;
	esac
	rc=$?
	secs=$(($(date +%s) - t0))
	p=$(grep -c '^ok ' "$log")
	s=$(grep -c '^\(not \)\{0,1\}ok [0-9]* *#* *# SKIP' "$log")
	f=$(grep '^not ok ' "$log" | grep -vc '# SKIP')
	p=$((p - $(grep -c '^ok [0-9]* *#* *# SKIP' "$log")))
	if [ "$rc" = 77 ]; then
		echo "SKIP $name: $(head -n 1 "$log")" > "$report"
		echo "0 0 1" > "$LOGDIR/$name.res"
	else
		[ "$rc" = 124 ] && echo "not ok - $name stopped after ${CHECK_TIMEOUT:-1800} s" >> "$log"
		if [ "$rc" != 0 ] && [ "$f" = 0 ]; then
			f=1   # crashed, timed out or failed outside a test case
		fi
		if [ "$f" != 0 ]; then
			{ echo "FAIL $name ($p passed, $f failed, $s skipped, exit $rc, ${secs} s):"
			  sed 's/^/    /' "$log"; } > "$report"
		else
			echo "ok   $name ($p passed, $s skipped, ${secs} s)" > "$report"
		fi
		grep '# SKIP' "$log" | sed "s/^/     $name: /" >> "$report"
		echo "$p $f $s" > "$LOGDIR/$name.res"
	fi
	flock "$LOGDIR/.print" cat "$report"
	exit 0
fi

# the order: long tests first, then the rest as given; "alone" tests last
first=""; rest=""; alone=""
for t in "$@"; do
	rm -f "$LOGDIR/$(basename "$t").res"
	case "$t" in
	*.sh) kind=$(sed -n 's/^# check: \(alone\|long\)$/\1/p' "$t" | head -n 1) ;;
	*)    kind="" ;;
	esac
	case "$kind" in
	long)  first="$first $t" ;;
	alone) alone="$alone $t" ;;
	*)     rest="$rest $t" ;;
	esac
done
# shellcheck disable=SC2086
printf '%s\n' $first $rest | grep . | xargs -r -P "$jobs" -n 1 sh "$here/run.sh" --one
for t in $alone; do
	sh "$here/run.sh" --one "$t"
done

pass=0; fail=0; skip=0; failed_files=""
for t in "$@"; do
	name=$(basename "$t")
	if [ -r "$LOGDIR/$name.res" ]; then
		read -r p f s < "$LOGDIR/$name.res"
	else
		p=0; f=1; s=0   # the runner itself lost it
	fi
	pass=$((pass + p)); fail=$((fail + f)); skip=$((skip + s))
	[ "$f" = 0 ] || failed_files="$failed_files $name"
done
[ -n "$failed_files" ] && echo "failed:$failed_files"
echo "check: $pass passed, $fail failed, $skip skipped"
[ "$fail" = 0 ]
