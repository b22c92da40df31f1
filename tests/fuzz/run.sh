#!/bin/sh
# SPDX-License-Identifier: ISC
# Run each libFuzzer binary given for at most SECONDS seconds, on its seed
# corpus (tests/fuzz/seeds/<name>/) plus a working corpus in $CORPUS/<name>.
# With RUNS (a number of executions, 0: none) a target stops when it has run
# that many, so a long run can ask for "1e6 executions per target" and let
# SECONDS be the limit that says it did not get there.
# Prints one line per target: executions, rate, seconds, whether it reached
# RUNS, and whether it crashed.  Exits non-zero if any target found a crash
# (its reproducer is kept) or, with RUNS, one fell short of RUNS.
secs=$1; shift
CORPUS=${CORPUS:-build-fuzz/corpus}
RUNS=${RUNS:-0}
status=0
printf '%-24s %12s %10s %8s %s\n' target executions exec/s seconds result
total=0
for bin in "$@"; do
	name=$(basename "$bin")
	mkdir -p "$CORPUS/$name" "$CORPUS/$name.crashes"
	seeds=tests/fuzz/seeds/$name
	[ -d "$seeds" ] || seeds=
	log="$CORPUS/$name.log"
	runs=
	[ "$RUNS" -gt 0 ] && runs="-runs=$RUNS"
	t0=$(date +%s%N)
	"$bin" -max_total_time="$secs" $runs -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 \
		-artifact_prefix="$CORPUS/$name.crashes/" "$CORPUS/$name" $seeds >"$log" 2>&1
	rc=$?
	t=$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.1f", (b - a) / 1e9 }')
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
	rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
	if [ "$rc" = 0 ]; then
		res="no crash"
		if [ "$RUNS" -gt 0 ] && [ "${execs:-0}" -lt "$RUNS" ]; then
			res="no crash, SHORT of $RUNS executions"
			status=1
		fi
	else
		res="CRASH (exit $rc; see $log)"
		status=1
		grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -n 5 | sed 's/^/    /'
	fi
	total=$((total + ${execs:-0}))
	printf '%-24s %12s %10s %8s %s\n' "$name" "${execs:-?}" "${rate:-?}" "$t" "$res"
done
printf '%-24s %12s\n' total "$total"
exit $status
