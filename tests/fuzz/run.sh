#!/bin/sh
# Run each libFuzzer binary given for SECONDS seconds, on its seed corpus
# (tests/fuzz/seeds/<name>/) plus a working corpus in $CORPUS/<name>.
# Prints one line per target: executions, and whether it crashed.
# Exits non-zero if any target found a crash (its reproducer is kept).
secs=$1; shift
CORPUS=${CORPUS:-build-fuzz/corpus}
status=0
printf '%-24s %12s %10s %s\n' target executions exec/s result
for bin in "$@"; do
	name=$(basename "$bin")
	mkdir -p "$CORPUS/$name" "$CORPUS/$name.crashes"
	seeds=tests/fuzz/seeds/$name
	[ -d "$seeds" ] || seeds=
	log="$CORPUS/$name.log"
	"$bin" -max_total_time="$secs" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 \
		-artifact_prefix="$CORPUS/$name.crashes/" "$CORPUS/$name" $seeds >"$log" 2>&1
	rc=$?
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
	rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
	if [ "$rc" = 0 ]; then
		res="no crash"
	else
		res="CRASH (exit $rc; see $log)"
		status=1
		grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -n 5 | sed 's/^/    /'
	fi
	printf '%-24s %12s %10s %s\n' "$name" "${execs:-?}" "${rate:-?}" "$res"
done
exit $status
