#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""The tree's structure rules (run by tests/system/005-structure.sh), judged on
the built objects (nm) and the sources.  Prints one line per violation,
"RULE: what", and nothing when the tree keeps the rules.

  structure.py BUILD TOP EXCEPTIONS ALLOW   the real tree
  structure.py --selftest                   each rule on a planted violation

EXCEPTIONS: lines "SYMBOL reason": symbols the prefix and header rules
accept.  ALLOW: lines "RULE SYMBOL-or-FILES": violations known and
tolerated for now (a temporary list).

Rules:
  prefix    an exported symbol of sim/**/X.c or drivers/X.c is ps_X or ps_X_*;
            of daemon/**/X.c, psd_X or psd_X_*
  basename  source basenames are unique across sim/, drivers/, daemon/
  header    X.c's exported symbols are declared in X.h beside it, and in no
            other header
  unused    an exported symbol is referenced by some other object (library
            member, program, unit test, emulator) or a fuzz target or bench
  cycle     no set of files of one library using each other's symbols
  stale     an entry of EXCEPTIONS or ALLOW that no longer matches anything
  room      the daemon's core includes a front end's room only through its
            public header; a room includes no other room's private header;
            psvirt's room is not in the core's library
"""
import os
import re
import subprocess
import sys

LIBS = {  # archive -> library name (the cycle rule is judged per library)
    "libpsim.a": "sim", "libpsdrv.a": "drivers", "libpsd.a": "daemon",
    "libpsdreport.a": "daemon", "libpsvirt.a": "daemon", "libpsdplace.a": "daemon",
}
ROOMS = {"report": "report.h", "psvirt": None, "place": None}   # room -> its public header
# a stand-in, built instead of X.c when X's library is left out, defines
# X.c's symbols (declared in X.h): it takes X's prefix and header
STANDINS = {}
# the front ends: each row &psd_X_frontend of daemon/frontend.c's table is
# a room daemon/X/ with its public header X.h, its library libpsdX.a and,
# when the folder has one, its stand-in X_off.c (added by add_frontends)
FRONTEND_ROW = re.compile(r"&psd_([a-z0-9]+)_frontend\b")


def add_frontends(top):
    """LIBS, ROOMS and STANDINS completed from the front-end table"""
    with open(os.path.join(top, "daemon", "frontend.c"), encoding="utf-8") as f:
        names = FRONTEND_ROW.findall(f.read())
    for x in names:
        LIBS["libpsd%s.a" % x] = "daemon"
        ROOMS[x] = "%s.h" % x
        if os.path.exists(os.path.join(top, "daemon", x, "%s_off.c" % x)):
            STANDINS["%s_off" % x] = x
    return names
EXPORTED = set("TDBRCGSV")


# Symbols a compiler instrumentation adds beside the program's own (ASan's
# ODR indicators "__odr_asan.NAME", its and UBSan's runtime, the fuzzer's
# coverage counters): never the program's names.
TOOL_SYMBOLS = ("__odr_asan", "__asan", "__ubsan", "__sanitizer", "__sancov", "__start___sancov", "__stop___sancov")


def nm(path):
    """[(member, kind, symbol)] of an object or archive: kind D defined, U used."""
    out = subprocess.run(["nm", "-A", path], capture_output=True, text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        parts = line.split(":")   # archive:member:rest, or object:rest
        if len(parts) < 2:
            continue
        member, rest = os.path.basename(parts[-2]), parts[-1]
        f = rest.split()
        if f and f[-1].startswith(TOOL_SYMBOLS):
            continue   # the sanitizers' and the fuzzer's own symbols
        if len(f) == 2 and f[0] == "U":
            rows.append((member, "U", f[1]))
        elif len(f) == 3 and f[1] in EXPORTED:
            rows.append((member, "D", f[2]))
    return rows


def sources(top):
    """basename -> [paths] of the .c files under sim/, drivers/, daemon/."""
    found = {}
    for d in ("sim", "drivers", "daemon"):
        for root, _, files in os.walk(os.path.join(top, d)):
            for f in files:
                if f.endswith(".c"):
                    found.setdefault(f[:-2], []).append(os.path.relpath(os.path.join(root, f), top))
    return found


def module_of(path):
    """the module a source belongs to: its basename, or the one it stands in for"""
    base = os.path.basename(path)[:-2]
    return STANDINS.get(base, base)


def source_of(srcs, lib, member):
    """the source of a library's member: under the library's folder; one
    made by the build (no source in the tree) is named for the library"""
    b = member[:-2]
    for p in srcs.get(b, []):
        if p.startswith(lib + "/"):
            return p
    return "%s/%s.c" % (lib, b)


def prefix_of(path, base):
    return ("psd_" if path.startswith("daemon/") else "ps_") + base


def rule_prefix(defs, exceptions):
    """defs: [(path, symbol)]"""
    for path, sym in defs:
        p = prefix_of(path, module_of(path))
        if sym != p and not sym.startswith(p + "_") and sym not in exceptions:
            yield "prefix: %s in %s (not %s_*)" % (sym, path, p)


def rule_basename(srcs):
    for base, paths in sorted(srcs.items()):
        if len(paths) > 1:
            yield "basename: %s.c in %s" % (base, " ".join(sorted(paths)))


def rule_header(defs, read, exceptions, headers):
    """read(path) -> the text of a header, or None; headers: every header's
    path (a symbol declared in another file's header is found there)"""
    for path, sym in defs:
        if sym in exceptions:
            continue
        h = os.path.join(os.path.dirname(path), module_of(path) + ".h")
        text = read(h)
        if text is None:
            yield "header: %s: %s has no %s" % (sym, path, h)
        elif not re.search(r"\b%s\b" % re.escape(sym), text):
            yield "header: %s not declared in %s" % (sym, h)
        decl = re.compile(r"^[A-Za-z_][^/*\n]*\b%s\s*[(\[;]" % re.escape(sym), re.M)
        for other in sorted(headers):
            if other != h and decl.search(read(other) or ""):
                yield "header: %s (%s) declared in %s" % (sym, path, other)


def rule_unused(defs_by_obj, uses_by_obj, named_elsewhere):
    """defs_by_obj/uses_by_obj: object -> set of symbols"""
    for obj, syms in sorted(defs_by_obj.items()):
        for sym in sorted(syms):
            if sym in named_elsewhere:
                continue
            if not any(sym in u for o, u in uses_by_obj.items() if o != obj):
                yield "unused: %s (%s): no other object uses it" % (sym, obj)


def cycles(defs, uses):
    """defs: symbol -> file; uses: file -> set of symbols.  Sets of files that
    use each other's symbols (strongly connected components of two or more)."""
    edges = {f: sorted({defs[s] for s in syms if s in defs and defs[s] != f}) for f, syms in uses.items()}
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, []):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(" ".join(sorted(comp)))

    sys.setrecursionlimit(10000)
    for v in sorted(set(edges) | set(defs.values())):
        if v not in index:
            visit(v)
    return out


def rule_cycle(lib, defs, uses):
    for c in cycles(defs, uses):
        yield "cycle: %s: %s" % (lib, c)


def room_of(path):
    """'' for the core (daemon/*), the room's name, or None (not daemon/, or cmd/)"""
    parts = path.split("/")
    if parts[0] != "daemon":
        return None
    if len(parts) == 2 or parts[1] == "cmd":
        return ""   # the core and its programs
    return parts[1] if parts[1] in ROOMS else None


def rule_room(includes, headers, members):
    """includes: [(path, header)] of daemon/ files; headers: header -> its
    path; members: [(archive, path)] of the daemon's archives."""
    for path, h in includes:
        mine, theirs = room_of(path), room_of(headers.get(h, ""))
        if mine is None or theirs is None or theirs == "" or theirs == mine:
            continue
        if h != ROOMS[theirs]:
            who = "the core" if mine == "" else "room %s" % mine
            yield "room: %s includes %s, private to room %s (%s)" % (path, h, theirs, who)
    for lib, path in members:
        if lib == "libpsd.a" and room_of(path) != "":
            yield "room: %s is in %s, the core's library" % (path, lib)


INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def tree(build, top, exceptions, allow):
    fronts = add_frontends(top)
    srcs = sources(top)
    found = list(rule_basename(srcs))
    if not fronts:
        found.append("room: daemon/frontend.c: no row &psd_X_frontend found")
    lib_rows = []   # (archive, path, kind, symbol)
    for a in sorted(LIBS):
        p = os.path.join(build, "lib", a)
        if os.path.exists(p):
            for member, kind, sym in nm(p):
                lib_rows.append((a, source_of(srcs, LIBS[a], member), kind, sym))
    defs = [(path, sym) for _, path, kind, sym in lib_rows if kind == "D"]

    def read(h):
        try:
            return open(os.path.join(top, h), encoding="utf-8").read()
        except OSError:
            return None

    found += rule_prefix(defs, exceptions)
    headers = []
    for d in ("sim", "drivers", "daemon"):
        for root, _, files in os.walk(os.path.join(top, d)):
            headers += [os.path.relpath(os.path.join(root, f), top) for f in files if f.endswith(".h")]
    found += rule_header(defs, read, exceptions, headers)
    # unused: every object of the build, the libraries' members by source path
    defs_by, uses_by = {}, {}
    for _, path, kind, sym in lib_rows:
        (defs_by if kind == "D" else uses_by).setdefault(path, set()).add(sym)
    members = {path for _, path, _, _ in lib_rows}
    objs = os.path.join(build, "obj")
    for root, _, files in os.walk(objs):
        for f in files:
            rel = os.path.relpath(os.path.join(root, f), objs)
            src = rel[:-2] + ".c"
            if not f.endswith(".o") or src in members:
                continue
            if not any(os.path.exists(os.path.join(d, src)) for d in (top, build)):
                continue   # an object left over from a source since moved or deleted
            for _, kind, sym in nm(os.path.join(root, f)):
                if kind == "U":
                    uses_by.setdefault(rel, set()).add(sym)
    # the fuzz targets and the benches are built by their own targets (make
    # fuzz, make bench), not by make check: their sources' words count
    fuzz = set()
    for sub in ("fuzz", "bench"):
        fdir = os.path.join(top, "tests", sub)
        for f in sorted(os.listdir(fdir)) if os.path.isdir(fdir) else []:
            if f.endswith(".c"):
                fuzz |= set(re.findall(r"\b\w+\b", open(os.path.join(fdir, f), encoding="utf-8").read()))
    found += rule_unused(defs_by, uses_by, fuzz)
    for lib in ("sim", "drivers", "daemon"):
        d, u = {}, {}
        for a, path, kind, sym in lib_rows:
            if LIBS[a] != lib:
                continue
            if kind == "D":
                d[sym] = path
            else:
                u.setdefault(path, set()).add(sym)
        found += rule_cycle(lib, d, u)
    # rooms: the includes of daemon/'s files
    includes, headers = [], {}
    for root, _, files in os.walk(os.path.join(top, "daemon")):
        for f in files:
            p = os.path.relpath(os.path.join(root, f), top)
            if f.endswith(".h"):
                headers[f] = p
            if f.endswith((".c", ".h")):
                includes += [(p, h) for h in INCLUDE.findall(read(p) or "")]
    members = sorted({(a, path) for a, path, _, _ in lib_rows if LIBS[a] == "daemon"})
    found += rule_room(includes, headers, members)
    keys = set()
    for line in found:
        key = allowed_key(line)
        keys.add(key)
        if key not in allow:
            print(line)
    # a list entry that matches nothing hides the next real violation: gone
    for key in sorted(allow - keys):
        print("stale: %s: in the temporary list, but no longer a violation" % key)
    for sym in sorted(exceptions - {sym for _, sym in defs}):
        print("stale: %s: an exception, but no library defines it" % sym)


def allowed_key(line):
    """'RULE WHAT': how the temporary list names a violation"""
    rule, _, rest = line.partition(": ")
    if rule == "cycle":
        return "cycle " + rest.split(": ", 1)[1]
    return rule + " " + rest.split()[0].rstrip(":")


def selftest():
    """Each rule on a planted violation and a case that keeps it."""
    def show(name, got):
        print(" | ".join(got) if got else name + ": none")
    ROOMS["mqtt"], STANDINS["mqtt_off"] = "mqtt.h", "mqtt"   # a front end, as add_frontends makes it
    show("prefix", list(rule_prefix([("sim/sky/sky.c", "ps_sky_sun"), ("sim/sky/sky.c", "ps_sun_az"),
                                     ("daemon/report/chart.c", "psd_chart"), ("daemon/db.c", "ps_db_open"),
                                     ("daemon/mqtt/mqtt_off.c", "psd_mqtt_open")], set())))
    show("basename", list(rule_basename({"a": ["sim/a.c"], "b": ["sim/b.c", "daemon/b.c"]})))
    hs = {"sim/sky/sky.h": "int ps_sky_sun(void);\n/* ps_sun is the sun */", "sim/sun2.h": "double ps_sky_sun(int);"}
    show("header", list(rule_header([("sim/sky/sky.c", "ps_sky_sun"), ("sim/sky/sky.c", "ps_sky_moon"), ("sim/sky/sun.c", "ps_sun")],
                                    hs.get, set(), sorted(hs))))
    show("unused", list(rule_unused({"sim/a.c": {"ps_a_used", "ps_a_self", "ps_a_fuzzed"}},
                                    {"sim/a.c": {"ps_a_self"}, "tests/unit/t.o": {"ps_a_used"}}, {"ps_a_fuzzed"})))
    show("cycle", list(rule_cycle("sim", {"fa": "a", "fb": "b", "fc": "c", "fd": "d"},
                                  {"a": {"fb"}, "b": {"fc"}, "c": {"fa", "fd"}})))
    heads = {"mqtt.h": "daemon/mqtt/mqtt.h", "mqttmsg.h": "daemon/mqtt/mqttmsg.h", "db.h": "daemon/db.h",
             "mbpdu.h": "daemon/psvirt/mbpdu.h", "report.h": "daemon/report/report.h"}
    show("room", list(rule_room([("daemon/loop.c", "mqtt.h"), ("daemon/engine.c", "mqttmsg.h"),
                                 ("daemon/mqtt/mqtt.c", "mqttmsg.h"), ("daemon/mqtt/mqtt.c", "db.h"),
                                 ("daemon/report/report.c", "mbpdu.h"), ("daemon/cmd/psensctl.c", "report.h")],
                                heads, [("libpsd.a", "daemon/db.c"), ("libpsd.a", "daemon/psvirt/mbpdu.c")])))


def words(path, n):
    """the first n words of each line of a list file (# starts a comment)"""
    out = set()
    for line in open(path, encoding="utf-8"):
        f = line.split("#", 1)[0].split()
        if f:
            out.add(" ".join(f[:n]) if n > 1 else f[0])
    return out


if __name__ == "__main__":
    if sys.argv[1:] == ["--selftest"]:
        selftest()
    else:
        build, top, exc, allow = sys.argv[1:5]
        allow_keys = set()
        for line in open(allow, encoding="utf-8"):
            f = line.split("#", 1)[0].split()
            if f:
                allow_keys.add(" ".join(f))
        tree(build, top, words(exc, 1), allow_keys)
