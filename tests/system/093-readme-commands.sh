#!/bin/sh
# SPDX-License-Identifier: ISC
# Every command line the README gives is run as written, in a copy of the
# tree and its build (so nothing is rebuilt and the user's build/ is left
# alone): the lines of its ```sh blocks (but make check, which is this run)
# and every `make run...` or `build/bin/...` span of its text.  Each must
# exit 0.  The walk-throughs in doc/ have tests of their own (222, 269,
# 311, 319).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
make -s deps > /dev/null 2>&1 ||
	skip_all "make run installs missing Debian packages first: not as this user"
awk '/^```sh$/ { on = 1; next } /^```/ { on = 0 } on { sub(/[ \t]*#.*/, ""); if ($0 != "") print }' README.md \
	| grep -v '^make check$' > "$TMP/lines"
grep -o '`\(make run[^`]*\|build/bin/[^`]*\)`' README.md | tr -d '`' >> "$TMP/lines"
sort -u "$TMP/lines" -o "$TMP/lines"
check "the README gives command lines: $(tr '\n' ';' < "$TMP/lines")" test "$(wc -l < "$TMP/lines")" -ge 3
mkdir -p "$TMP/tree"
git ls-files -z 2>/dev/null | xargs -0 cp -a --parents -t "$TMP/tree" 2>/dev/null ||
	tar -cf - --exclude=./.git --exclude="./$BUILD" --exclude=./build . | tar -xf - -C "$TMP/tree"
mkdir -p "$TMP/tree/build"
cp -a "$BUILD/." "$TMP/tree/build/"
rm -f "$TMP/tree/build/psensd.db"* "$TMP/tree/build/build.log"
# a make inside make check keeps MAKEFLAGS (the build's variables: SAN=1
# and BUILD in CI), so the build it names is this same copy
[ "$BUILD" = build ] || ln -s build "$TMP/tree/$BUILD"
i=0
while IFS= read -r line; do
	i=$((i + 1))
	(cd "$TMP/tree" && env -u BUILD -u BIN sh -c "$line") > "$TMP/out.$i" 2> "$TMP/err.$i"
	rc=$?
	check "README: '$line' exits 0 ($rc$( [ $rc = 0 ] || printf ': %s' "$(tail -n 2 "$TMP/err.$i" | tr '\n' ' ')"))" test "$rc" = 0
done < "$TMP/lines"
done_testing
