#!/bin/sh
# SPDX-License-Identifier: ISC
# Every source file says its licence in an SPDX line: "SPDX-License-Identifier:
# ISC" in its first 5 lines (C and headers, shell, Python, Makefile and
# module.mk files).  The data directories that keep their own licences
# (sim/data/cie, tests/data/gendaymtx: see README.md, "Licence") hold no such
# files; build trees, .git and npm's node_modules are skipped.
. "$(dirname "$0")/lib.sh"
cd "$TOP" || skip_all "no source tree at $TOP"
[ -f LICENSE ] || skip_all "not a source tree (no LICENSE) at $TOP"

find . \( -name .git -o -name 'build*' -o -name '.cache' -o -name node_modules \) -prune -o -type f \
	\( -name '*.c' -o -name '*.h' -o -name '*.sh' -o -name '*.py' -o -name Makefile \
	   -o -name module.mk \) -print | sed 's|^\./||' | sort > "$TMP/files"
n=$(wc -l < "$TMP/files")
check "found the source files ($n)" test "$n" -gt 100
missing=0
while read -r f; do
	if ! head -n 5 "$f" | grep -q 'SPDX-License-Identifier: ISC'; then
		missing=$((missing + 1))
		[ "$missing" -le 20 ] && diag "no 'SPDX-License-Identifier: ISC' in the first 5 lines: $f"
	fi
done < "$TMP/files"
[ "$missing" -gt 20 ] && diag "... and $((missing - 20)) more"
check "every source file has an ISC SPDX line in its first 5 lines ($missing missing)" test "$missing" = 0
check "LICENSE is the ISC licence" grep -q '^ISC License' LICENSE
done_testing
