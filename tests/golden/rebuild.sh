#!/bin/sh
# SPDX-License-Identifier: ISC
# make golden: run the example day again, say how it differs from the golden
# one (per column against the tolerances of compare.py, the summary lines,
# and the commits since the golden day was last written that touch the code
# it runs), then write it to tests/data/golden-day.csv and .summary.
set -eu
BUILD=${BUILD:-build}
tmp=$(mktemp -d /tmp/psgold.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
sh tests/golden/day.sh "$tmp"
gold=tests/data/golden-day.csv
if [ -f "$gold" ]; then
	echo "== the new day against the golden one"
	/usr/bin/python3 tests/golden/compare.py --report "$gold" "$tmp/day.csv"
	echo "== the summary (- golden, + now)"
	diff -u tests/data/golden-day.summary "$tmp/day.summary" | sed -n '3,$p' | grep '^[-+]' || echo "   (unchanged)"
	if git rev-parse --git-dir > /dev/null 2>&1; then
		last=$(git log -1 --format=%h -- "$gold" 2>/dev/null || true)
		if [ -n "$last" ]; then
			echo "== commits since $last (the golden day's last change) touching what it runs"
			git log --oneline "$last..HEAD" -- sim drivers daemon config | sed 's/^/   /'
			git status --short -- sim drivers daemon config | sed 's/^/   uncommitted: /'
		fi
	fi
else
	echo "== no golden day yet: writing it"
fi
cp "$tmp/day.csv" "$gold"
cp "$tmp/day.summary" tests/data/golden-day.summary
echo "wrote $gold ($(($(wc -l < "$gold") - 1)) samples) and tests/data/golden-day.summary"
