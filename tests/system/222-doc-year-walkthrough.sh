#!/bin/sh
# SPDX-License-Identifier: ISC
# doc/year.md's command lines run as written, from the top of a fresh copy
# of the tree with build/bin the binaries under test: the pssky example
# (the cd it needs is written out) prints the document's lines, and the
# rooftop walk-through runs on the shipped config/example/rooftop.conf and
# gives the document's estimate and sky classes.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
BINABS=$(cd "$BIN" && pwd)
mkdir -p "$TMP/top/config" "$TMP/top/build" "$TMP/top/tests/data"
cp -R config/example "$TMP/top/config/"
cp -R tests/data/gendaymtx "$TMP/top/tests/data/"
ln -s "$BINABS" "$TMP/top/build/bin"
# block N of the document: its "$ " lines as a script, its first other line
cmds() { awk -v n="$1" '/^```/ { if (++k == 2 * n) exit; next } k == 2 * n - 1 && /^\$ / { sub(/^\$ /, ""); print }' doc/year.md; }
first() { awk -v n="$1" '/^```/ { if (++k == 2 * n) exit; next } k == 2 * n - 1 && !/^\$ / { print; exit }' doc/year.md; }
# the blocks holding the two walk-throughs
nsky=$(awk '/^```/ { k++ } /^\$ .*pssky -v -r 90/ { print (k + 1) / 2; exit }' doc/year.md)
nroof=$(awk '/^```/ { k++ } /^\$ .*rooftop.conf -s/ { print (k + 1) / 2; exit }' doc/year.md)
check "doc/year.md has both walk-throughs (blocks $nsky and $nroof)" test -n "$nsky" -a -n "$nroof"
cmds "$nsky" > "$TMP/sky.sh"
check "the pssky example says its cd: $(tr '\n' ';' < "$TMP/sky.sh")" grep -q '^cd tests/data/gendaymtx' "$TMP/sky.sh"
got=$(cd "$TMP/top" && sh "$TMP/sky.sh" 2>&1 | head -n 1)
check "run as written it prints the document's first line ($got)" test "$got" = "$(first "$nsky")"
cmds "$nroof" > "$TMP/roof.sh"
check "the rooftop walk-through runs the shipped configuration" grep -q '^build/bin/psensd -f config/example/rooftop.conf -s' "$TMP/roof.sh"
(cd "$TMP/top" && sh "$TMP/roof.sh") > "$TMP/roof.out" 2> "$TMP/roof.err"; rc=$?
check "it runs as written (exit $rc)" test "$rc" = 0
want=$(awk '/^\$ .*rooftop.conf -s/ { f = 1; next } f && /estimated against/ { print; exit }' doc/year.md)
check "the document's estimate: $want" grep -qF "$want" "$TMP/roof.out"
# the document's sky classes: the lines after its sqlite3 command
awk '/^\$ sqlite3 build\/rooftop.db/ { f = 1; next } f && /^```/ { exit } f' doc/year.md > "$TMP/classes"
check "the document gives sky classes ($(tr '\n' ' ' < "$TMP/classes"))" test -s "$TMP/classes"
while read -r c; do
	check "the document's sky classes: $c" grep -qxF "$c" "$TMP/roof.out"
done < "$TMP/classes"
done_testing
