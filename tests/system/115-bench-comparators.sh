#!/bin/sh
# SPDX-License-Identifier: ISC
# The benchmarks state CPU seconds, or a ratio against a comparator measured
# in the same run (cold against warm, one route against another): never
# against a figure remembered from another tool's run on another day
# (Radiance is not installed where they run).  The benchmarks' sources and
# doc/performance.md, which quotes their tables, are searched for such a
# figure: a Radiance time in seconds, or a ratio column over one.
. "$(dirname "$0")/lib.sh"
cd "$TOP" || exit 1
hits=$(grep -n -i -E "radiance[^.]*[0-9.]+ s( |,|\)|$)|radiance('s)? ?(/|over) ?psens|radiance_(wall|cpu)|x: radiance|[0-9.]+ s cpu at [0-9]+x" \
	tests/bench/* doc/performance.md)
[ -z "$hits" ] || printf '%s\n' "$hits" | sed 's/^/# /'
check "no ratio or goal against a remembered Radiance time ($(printf '%s' "$hits" | grep -c .))" \
	test -z "$hits"
# the azimuthal benchmark's warm rows are compared with its cold ones
check "bench_weights_azimuth states CPU seconds" grep -q '"cpu s"' tests/bench/bench_weights_azimuth.c
check "bench_weights_azimuth compares warm with the same run's cold" \
	grep -q 'cold / warm' tests/bench/bench_weights_azimuth.c
done_testing
