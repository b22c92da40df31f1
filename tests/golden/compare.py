#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""Compare an exported day (psensctl export --csv) with the golden one.

  compare.py GOLDEN NEW          exit 1 when a column is outside its tolerance
  compare.py --report GOLDEN NEW the same table, exit 0 (make golden: why it changed)

Tolerances, per column (absolute unless said; see tests/golden/README.md):
each is at least 1000 times what two correct builds can differ by (the
CSV's 10 significant digits, gcc against clang, one libm against another:
1e-9 relative at most) and at least 100 times smaller than the smallest
change that means different behaviour (the room's sensor noise 0.002 V,
the 2 % below-target margin of 10 lx, one DALI step of 2.8 % of output).
"""
import csv
import sys

TOL = {
    "t": 0, "tod_s": 0,          # the simulated clock: exact
    "sensor_v": 1e-5,            # volts; the noise is 0.002 V
    "output": 1e-5,              # fraction of full output
    "est_task_lux": 0.01,        # lux; the target is 500 lx
    "task_lux": 0.01,
    "daylight_v": 1e-5,
    "daylight_lux": 0.01,
    "ratio": 1e-6,               # relative: task lux per unit of response
}
EXACT = ("condition", "fault", "zone")   # strings: equal


def hhmm(tod):
    try:
        s = int(float(tod))
    except ValueError:
        return "?"
    return "%02d:%02d" % (s // 3600, s // 60 % 60)


def num(s):
    return None if s == "" else float(s)


def main(argv):
    report = argv[1:2] == ["--report"]
    args = argv[2:] if report else argv[1:]
    if len(args) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    with open(args[0], newline="") as f:
        gold = list(csv.DictReader(f))
    with open(args[1], newline="") as f:
        new = list(csv.DictReader(f))
    bad = 0
    if len(gold) != len(new):
        print("rows: %d golden, %d now" % (len(gold), len(new)))
        bad += 1
    cols = [c for c in (gold[0].keys() if gold else []) if c in TOL or c in EXACT]
    print("%-14s %10s %8s %14s %6s" % ("column", "tolerance", "outside", "largest diff", "at"))
    for c in cols:
        out, worst, at = 0, 0.0, ""
        for g, n in zip(gold, new):
            if c in EXACT:
                if g.get(c) != n.get(c):
                    out += 1
                    if not at:
                        at = hhmm(g["tod_s"])
                continue
            a, b = num(g.get(c, "")), num(n.get(c, ""))
            if a is None or b is None:
                if (a is None) != (b is None):
                    out += 1
                    at = at or hhmm(g["tod_s"])
                continue
            d = abs(a - b)
            if c == "ratio":
                d /= max(abs(a), 1e-300)
            if d > worst:
                worst, at_w = d, hhmm(g["tod_s"])
                if d > TOL[c]:
                    at = at_w
            if d > TOL[c]:
                out += 1
        tol = "exact" if c in EXACT else ("%g rel" % TOL[c] if c == "ratio" else "%g" % TOL[c])
        big = "" if c in EXACT else "%.3g" % worst
        print("%-14s %10s %8d %14s %6s" % (c, tol, out, big, at if out else ""))
        bad += out
    print("golden day: %s" % ("the same within the tolerances" if bad == 0 else "%d values differ" % bad))
    return 0 if report or bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
