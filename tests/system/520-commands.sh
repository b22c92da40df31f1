#!/bin/sh
# SPDX-License-Identifier: ISC
# Commands that agree: every program (sim/cmd/*.c, daemon/cmd/*.c,
# daemon/place/psplace.c, daemon/psvirt/psvirt.c) takes -h/--help (usage on standard output, exit 0)
# and -V/--version (the version of sim/version.h); its --help and its man
# page name the same options (tests/system/opts.py); the old spellings still
# work, with a warning; no option is silently ignored.
. "$(dirname "$0")/lib.sh"
version=$(sed -n 's/^#define PS_VERSION "\(.*\)"$/\1/p' sim/version.h)
[ -n "$version" ] || skip_all "no PS_VERSION in sim/version.h"

for src in sim/cmd/*.c daemon/cmd/*.c daemon/place/psplace.c daemon/psvirt/psvirt.c; do
	p=$(basename "$src" .c)
	if [ ! -x "$BIN/$p" ]; then
		skip "$p not built"
		continue
	fi
	man=$(ls "${src%.c}".[1-8] 2>/dev/null | head -n 1)
	for h in -h --help; do
		"$BIN/$p" $h > "$TMP/out" 2> "$TMP/err"; rc=$?
		check "$p $h: exit 0 ($rc), usage on standard output, nothing on standard error" \
			sh -c "[ $rc = 0 ] && grep -q '^usage: $p' '$TMP/out' && [ ! -s '$TMP/err' ]"
	done
	for v in -V --version; do
		out=$("$BIN/$p" $v 2>&1); rc=$?
		check "$p $v: exit 0 ($rc), '$out'" test "$rc:$out" = "0:$p (psensd) $version"
	done
	if [ -z "$man" ]; then
		not_ok "$p has no man page beside its source"
		continue
	fi
	diff=$(python3 tests/system/opts.py "$BIN/$p" "$man"); rc=$?
	check "$p --help and $man name the same options ($diff)" test "$rc" = 0
	check "$man describes the command-line conventions" grep -q '^\.SH COMMAND-LINE CONVENTIONS' "$man"
done

# the checker itself: a help naming an option the page lacks is found
printf '#!/bin/sh\necho "usage: fake [-a] [-b]"\n' > "$TMP/fake"; chmod +x "$TMP/fake"
printf '.SH SYNOPSIS\n.B fake\n.RB [ \\-a ]\n.SH OPTIONS\n.TP\n.B \\-a\nA.\n' > "$TMP/fake.1"
check "opts.py finds -b missing from a page: $(python3 tests/system/opts.py "$TMP/fake" "$TMP/fake.1")" \
	sh -c "! python3 tests/system/opts.py '$TMP/fake' '$TMP/fake.1' > /dev/null"

# ---- the old spellings: the same result as the new, and a warning --------------------
SEN=config/example/ofb/sensors/cosine.sen
if [ -x "$BIN/mksens" ]; then
	"$BIN/mksens" -S 32 --rotation 30 "$SEN" > "$TMP/new.hdr" 2> "$TMP/new.err"
	"$BIN/mksens" -r 32 -o 30 "$SEN" > "$TMP/old.hdr" 2> "$TMP/old.err"
	check "mksens -r 32 -o 30 (old) draws what -S 32 --rotation 30 does" cmp -s "$TMP/new.hdr" "$TMP/old.hdr"
	check "mksens: the new spelling gives no warning" test ! -s "$TMP/new.err"
	check "mksens -r warns: $(grep -- '-r as' "$TMP/old.err")" grep -q 'warning: -r as the resolution is deprecated.*use -S' "$TMP/old.err"
	check "mksens -o DEG warns: $(grep -- '-o as' "$TMP/old.err")" grep -q 'warning: -o as the rotation is deprecated.*use --rotation' "$TMP/old.err"
	# -o FILE is the output file, as in pspng and psshare
	"$BIN/mksens" -S 32 -o "$TMP/o.hdr" "$SEN" 2> "$TMP/o.err"
	"$BIN/mksens" -S 32 "$SEN" > "$TMP/so.hdr"
	check "mksens -o FILE writes the file (as > FILE would), no warning" \
		sh -c "cmp -s '$TMP/o.hdr' '$TMP/so.hdr' && [ ! -s '$TMP/o.err' ]"
fi
WEA=tests/data/gendaymtx/test.wea
if [ -x "$BIN/pssky" ]; then
	"$BIN/pssky" -H -m 1 "$WEA" > "$TMP/H.mtx" 2> "$TMP/H.err"
	"$BIN/pssky" -h -m 1 "$WEA" > "$TMP/h.mtx" 2> "$TMP/h.err"
	check "pssky -h FILE (old no-header) writes what -H does, no header" \
		sh -c "cmp -s '$TMP/H.mtx' '$TMP/h.mtx' && ! grep -q '^#?RADIANCE' '$TMP/h.mtx' && [ -s '$TMP/h.mtx' ]"
	check "pssky -h FILE warns: $(cat "$TMP/h.err")" grep -q 'warning: -h as gendaymtx.s no-header is deprecated.*use -H' "$TMP/h.err"
	check "pssky -H: no warning" test ! -s "$TMP/H.err"
fi
if [ -x "$BIN/psvirt" ]; then
	example_results > /dev/null
	"$BIN/psvirt" --results "$TMP/state/ofb.results" --tcp 127.0.0.1:1 -D gian=2 > /dev/null 2> "$TMP/D.err"
	"$BIN/psvirt" --results "$TMP/state/ofb.results" --tcp 127.0.0.1:1 -o gian=2 > /dev/null 2> "$TMP/o.err"
	check "psvirt -D KEY=VALUE is a room option: $(cat "$TMP/D.err")" grep -q -- '-D gian: not a loopback room option' "$TMP/D.err"
	check "psvirt -o KEY=VALUE (old) is the same option" grep -q -- '-D gian: not a loopback room option' "$TMP/o.err"
	check "psvirt -o warns: $(grep warning "$TMP/o.err")" grep -q 'warning: -o KEY=VALUE is deprecated.*use -D' "$TMP/o.err"
	check "psvirt -D: no warning" sh -c "! grep -q warning '$TMP/D.err'"
fi

# ---- no option silently ignored ----------------------------------------------------
if [ -x "$BIN/psensd" ]; then
	"$BIN/psensd" -f config/psensd.conf -s -x 600 > "$TMP/out" 2> "$TMP/err"; rc=$?
	check "psensd -s -x 600: exit 2 ($rc): $(cat "$TMP/err")" \
		sh -c "[ $rc = 2 ] && grep -q -- '-x sets the real-time clock, which -s does not run' '$TMP/err' && [ ! -s '$TMP/out' ]"
	"$BIN/psensd" -f config/psensd.conf -n -t 06:00 > "$TMP/out" 2> "$TMP/err"; rc=$?
	check "psensd -n -t 06:00: exit 2 ($rc): $(cat "$TMP/err")" \
		sh -c "[ $rc = 2 ] && grep -q -- '-t sets the real-time clock, which -n does not run' '$TMP/err'"
	"$BIN/psensd" -f config/psensd.conf -P "$TMP/y.png" > /dev/null 2> "$TMP/err"; rc=$?
	check "psensd -P without -Y: exit 2 ($rc): $(cat "$TMP/err")" sh -c "[ $rc = 2 ] && grep -q 'goes with -Y' '$TMP/err'"
	"$BIN/psensd" -f config/psensd.conf -Y -x 600 > /dev/null 2> "$TMP/err"; rc=$?
	check "psensd -Y -x 600: exit 2 ($rc): $(cat "$TMP/err")" sh -c "[ $rc = 2 ] && grep -q -- '-x sets the real-time clock, which -Y does not run' '$TMP/err'"
	"$BIN/psensd" -n -s > /dev/null 2> "$TMP/err"; rc=$?
	check "psensd -n -s: exit 2 ($rc): $(cat "$TMP/err")" sh -c "[ $rc = 2 ] && grep -q 'one or the other' '$TMP/err'"
fi
if [ -x "$BIN/psensctl" ]; then
	"$BIN/psensctl" -s "$TMP/none.sock" -d "$TMP/x.db" status > /dev/null 2> "$TMP/err"; rc=$?
	check "psensctl -d db status: exit 2 ($rc): $(cat "$TMP/err")" \
		sh -c "[ $rc = 2 ] && grep -q -- '-d is for export, report, log and accept-test' '$TMP/err'"
fi

# ---- the man pages as a reader sees them ---------------------------------------------
if command -v man > /dev/null; then
	MANWIDTH=200 LC_ALL=C.UTF-8 man -l daemon/cmd/psensctl.1 2>/dev/null | grep 'new target' > "$TMP/target"
	check "psensctl(1): the target's range reads 0 to 1000000 lux: $(cat "$TMP/target")" \
		grep -q '0 to 1000000 lux' "$TMP/target"
	MANWIDTH=200 man -l sim/cmd/psens.1 2>/dev/null | grep -A2 -- '^ *-f filter' | tr -s ' ' > "$TMP/f"
	check "psens(1) documents -f" grep -q 'colour filter' "$TMP/f"
	MANWIDTH=200 man -l sim/cmd/psfilter.1 2>/dev/null | tr -s ' \n' '  ' > "$TMP/pf"
	check "psfilter(1) and its help agree: percent when a value exceeds 2" \
		sh -c "grep -q 'exceeds 2 is read as percent' '$TMP/pf' && '$BIN/psfilter' -h | grep -q 'percent if any exceeds 2'"
else
	skip "man not installed: the pages' rendering is not checked"
fi
done_testing
