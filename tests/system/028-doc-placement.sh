#!/bin/sh
# SPDX-License-Identifier: ISC
# doc/placement.md's run on the shipped fixture, as the document gives it:
# the commands of its code block (every "$ " line and the lines its
# trailing backslashes continue), in order, as one script, from the top of
# a copy of the tree's config/ and tests/data/ofb-place with build/bin the
# binaries under test.  They must run, and every line the document prints
# for them (the table's rows and header, the exact re-check, the zone
# section; not the time line, which is the machine's) must be one the run
# prints; the prose's winner (its energy and hours below 90 %) must be the
# run's rank 1.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
BINABS=$(cd "$BIN" && pwd)
mkdir -p "$TMP/top/config" "$TMP/top/build" "$TMP/top/tests/data"
cp -R config/example config/psensd.conf "$TMP/top/config/"
cp -R tests/data/ofb-place "$TMP/top/tests/data/"
ln -s "$BINABS" "$TMP/top/build/bin"
# the section's code block: commands (with their continuations) and output
awk '/^## A run on the shipped fixture/ { s = 1; next } /^## / { s = 0 }
     s && /^```/ { b = !b; next }
     s && b && (/^\$ / || cont) { l = $0; sub(/^\$ /, "", l); print l; cont = /\\$/ }' \
	doc/placement.md > "$TMP/walk.sh"
awk '/^## A run on the shipped fixture/ { s = 1; next } /^## / { s = 0 }
     s && /^```/ { b = !b; next }
     s && b && /^\$ / { cont = /\\$/; next }
     s && b && cont { cont = /\\$/; next }
     s && b && !/^time: / { print }' doc/placement.md > "$TMP/want"
diag "the example's commands:"
while IFS= read -r l; do diag "  $l"; done < "$TMP/walk.sh"
check "doc/placement.md gives the commands ($(wc -l < "$TMP/walk.sh") lines)" grep -q "^build/bin/psplace -f config/psensd.conf" "$TMP/walk.sh"
check "and the output they print ($(wc -l < "$TMP/want") lines)" test "$(wc -l < "$TMP/want")" -ge 15
(cd "$TMP/top" && sh -e "$TMP/walk.sh") > "$TMP/out" 2> "$TMP/err"; rc=$?
check "they run as written (exit $rc)" test "$rc" = 0
diag "$(cat "$TMP/err")"
n=0
while IFS= read -r l; do
	n=$((n + 1))
	check "document line $n is the run's: $l" grep -qxF -- "$l" "$TMP/out"
done < "$TMP/want"
# the prose's winner against the run's rank 1
r1=$(awk '$1 == "1" && NF >= 13 { print $6, $8; exit }' "$TMP/out")
e=${r1% *}; h=${r1#* }
check "the page's winner uses $e % with $h h below 90 % (the run's rank 1)" \
	sh -c "tr '\n' ' ' < doc/placement.md | grep -q 'wins: its [a-z-]* law uses $e % of full power with $h occupied hours below'"
done_testing
