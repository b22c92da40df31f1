#!/bin/sh
# SPDX-License-Identifier: ISC
# make run, the README's command: quiet by default (no build commands before
# the summary: they go to BUILD/build.log), V=1 shows the commands.  Run in
# a copy of the tree: make check writes nothing into the user's build/.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
make -s deps > /dev/null 2>&1 ||
	skip_all "make run installs missing Debian packages first: not as this user"
# make run writes the example's results and log into build/ and its build
# into BUILD: run in a copy of the tree and of the build (times kept, so
# nothing is rebuilt), never into the user's tree
mkdir -p "$TMP/tree"
git ls-files -z 2>/dev/null | xargs -0 cp -a --parents -t "$TMP/tree" 2>/dev/null ||
	tar -cf - --exclude=./.git --exclude="./$BUILD" --exclude=./build . | tar -xf - -C "$TMP/tree"
cp -a "$BUILD/." "$TMP/tree/b/"
rm -f "$TMP/tree/b/build.log"
# one source of each stage newer than the build: the quiet build has work to
# show progress for (a line a stage, on standard error)
touch "$TMP/tree/sim/cache.c" "$TMP/tree/daemon/log.c"
before=$(ls -l --time-style=+%s.%N build/psensd.db build/ofb.results 2>/dev/null | md5sum)
TOPDIR=$(pwd)
cd "$TMP/tree"
BUILD=b
# as a user sees it: inside make check this make is a sub-make, which GNU
# make announces ("Entering directory") unless told not to; MAKEFLAGS stays,
# it carries the build's variables (SAN=1 in CI)
make --no-print-directory BUILD="$BUILD" run > "$TMP/out" 2> "$TMP/err"; rc=$?
check "make run: exit 0 ($rc)" test "$rc" = 0
check "make run: its first line on standard output is the summary: $(head -n 1 "$TMP/out")" \
	grep -Eq '^psensd: simulated [0-9]{4}-03-[0-9]{2} 06:00 to [0-9-]+ 20:00 [(]14 h 0 min; the room.s day 03-18[)] on the loopback room' "$TMP/out"
check "make run: no command shown ($(grep -c 'psensd -f\|^make\|^cc ' "$TMP/out" "$TMP/err" | tr '\n' ' '))" \
	sh -c "! grep -q 'psensd -f\|^make\|^cc \|Entering directory' '$TMP/out' '$TMP/err'"
check "make run: the build's output is kept in $BUILD/build.log" test -f "$BUILD/build.log"
check "make run: a progress line for the simulation's stage ($(grep -c '^building' "$TMP/err") lines)" \
	grep -q '^building the simulation library and its tools' "$TMP/err"
check "make run: a progress line for psensd's stage" grep -q '^building psensd and its front ends' "$TMP/err"
check "make run: the progress before the summary, not on its standard output" \
	sh -c "! grep -q '^building' '$TMP/out'"
# the test peers (npm) are make check's, not the main command's
check "make run: npm not run ($(grep -c 'added [0-9]* packages' "$TMP/out" "$TMP/err" | tr '\n' ' '))" \
	sh -c "! grep -q 'added [0-9]* packages' '$TMP/out' '$TMP/err' && [ ! -d tests/peers/node_modules ]"
make --no-print-directory BUILD="$BUILD" run V=1 > "$TMP/vout" 2> "$TMP/verr"; rc=$?
check "make run V=1: exit 0 ($rc), shows the build and the command run" \
	sh -c "[ $rc = 0 ] && grep -q '^make all' '$TMP/vout' && grep -q '^$BUILD/bin/psensd -f config/psensd.conf -s' '$TMP/vout'"
check "make run V=1: the summary still printed" grep -q '^psensd: simulated [0-9-]* 06:00 to' "$TMP/vout"
check "make run ran in the copy: its log is there" test -s "$TMP/tree/build/psensd.db"
cd "$TOPDIR"
check "the user's build/psensd.db and build/ofb.results are untouched" \
	test "$(ls -l --time-style=+%s.%N build/psensd.db build/ofb.results 2>/dev/null | md5sum)" = "$before"
done_testing
