#!/bin/sh
# SPDX-License-Identifier: ISC
# The daemon's structure, checked on the built objects and the sources:
# no two daemon files use each other's symbols (directly or round a longer
# cycle), the calibration side does not include the engine, and daemon/
# reaches devices only through the driver table (no loopback.h, and room.h
# only in roomsetup.c, the one place that builds the simulated room; psvirt
# opens its rooms through the registry like psensd).
. "$(dirname "$0")/lib.sh"
[ -f "$BUILD/lib/libpsd.a" ] || skip_all "the daemon's library is not built"
command -v nm > /dev/null || skip_all "nm not installed"

# every daemon object's defined and undefined symbols: "FILE D|U SYMBOL"
# (the members of libpsd.a: the daemon's files but its programs)
nm -A "$BUILD/lib/libpsd.a" | sed 's/^[^:]*:\([^:]*\)\.o:/\1 /' |
	awk '$2 == "U" { print $1, "U", $3; next } NF == 4 && $3 ~ /[TDBRC]/ { print $1, "D", $4 }' > "$TMP/syms"
# cycles SYMS: each set of files that use each other's symbols, one a line
cycles() {
/usr/bin/python3 - "$1" <<'PY'
import sys
defs, uses = {}, {}
for line in open(sys.argv[1]):
    f, kind, sym = line.split()
    if kind == "D":
        defs[sym] = f
    else:
        uses.setdefault(f, set()).add(sym)
edges = {f: sorted({defs[s] for s in syms if s in defs and defs[s] != f}) for f, syms in uses.items()}
# Tarjan's strongly connected components: a component of two or more files is a cycle
index, low, stack, on, out, n = {}, {}, [], set(), [], [0]
def visit(v):
    index[v] = low[v] = n[0]; n[0] += 1; stack.append(v); on.add(v)
    for w in edges.get(v, []):
        if w not in index:
            visit(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop(); on.discard(w); comp.append(w)
            if w == v:
                break
        if len(comp) > 1:
            out.append(" ".join(sorted(comp)))
sys.setrecursionlimit(10000)
for v in sorted(set(edges) | set(defs.values())):
    if v not in index:
        visit(v)
for c in out:
    print(c)
PY
}
cycles "$TMP/syms" > "$TMP/cycles"
check "no cycle between daemon files (symbols of $(cut -d' ' -f1 "$TMP/syms" | sort -u | wc -l) files)$(sed 's/^/: /' "$TMP/cycles" | tr '\n' ' ')" \
	test ! -s "$TMP/cycles"
# the check itself: a round a -> b -> c -> a is found, a use of d is not
printf 'a D fa\na U fb\nb D fb\nb U fc\nc D fc\nc U fa\nc U fd\nd D fd\n' > "$TMP/synthetic"
check "the check finds a cycle of three files: $(cycles "$TMP/synthetic")" test "$(cycles "$TMP/synthetic")" = "a b c"

inc() { grep -l "#include \"$1\"" "$TOP"/daemon/*.c "$TOP"/daemon/*.h "$TOP"/daemon/cmd/*.c 2>/dev/null | sed "s|$TOP/||" | sort | tr '\n' ' '; }
check "loopback.h nowhere in daemon/: $(inc loopback.h)" test -z "$(inc loopback.h)"
check "room.h only in roomsetup.c: $(inc room.h)" test "$(inc room.h)" = "daemon/roomsetup.c "
check "the calibration side does not include engine.h" \
	sh -c "! grep -l '#include \"engine.h\"' '$TOP'/daemon/calsession.[ch] '$TOP'/daemon/calfit.[ch] '$TOP'/daemon/db.[ch]"
done_testing
