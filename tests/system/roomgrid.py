# SPDX-License-Identifier: ISC
"""The test grids' daylight and electric light as psplace's exports give
them, computed independently of psplace for tests 022 and 024 (imported
with PYTHONPATH=tests/system).  A test grid's point p has the first
point's daylight coefficients times scale[p] and an electric illuminance
of x[p] W/m2 in each channel."""

# V(lambda)'s weights of the three channels, and lux per W/m2
V = (0.265074126, 0.670114631, 0.064811243)
LUX_PER_WM2 = 179.0


def elec_lux(x):
    """Each point's electric illuminance in lx from its W/m2 per channel."""
    return [LUX_PER_WM2 * (V[0] * v + V[1] * v + V[2] * v) for v in x]


def year_hours(results, divisor):
    """The results file's [year_hours], as {(month, day): [(second of the
    day, task lux / divisor)]}: psplace writes the grid's figure as the
    task, so dividing by the figure of the scales gives the first point's."""
    hours = {}
    inyear = False
    for line in open(results):
        if line.startswith('['):
            inyear = line.strip() == '[year_hours]'
            continue
        if inyear and line.startswith('h'):
            f = line.split('=')[1].split()
            m, dd, h, task = int(f[0]), int(f[1]), float(f[2]), float(f[4])
            hours.setdefault((m, dd), []).append((3600.0 * h, task / divisor))
    return hours


def daylight(hours, day, tod):
    """The first point's daylight at tod as the room makes the day's
    points: linear between the hours, dark an hour (or a step) before the
    first and after the last."""
    hs = hours.get(day)
    if not hs:
        return 0.0
    step = 3600.0
    if len(hs) > 1 and 0 < hs[1][0] - hs[0][0] < step:
        step = hs[1][0] - hs[0][0]
    pts = [(max(0.0, hs[0][0] - step), 0.0)] + hs + [(min(86400.0, hs[-1][0] + step), 0.0)]
    if tod < pts[0][0] or tod > pts[-1][0]:
        return 0.0
    for (t0, v0), (t1, v1) in zip(pts, pts[1:]):
        if t0 <= tod <= t1:
            return v0 + (tod - t0) / (t1 - t0) * (v1 - v0)
    return 0.0


def occupied_hours(csv, occupied_h):
    """The year CSV's occupied hours (from 08:00, occupied_h a day) as
    (month, day, second the hour starts, light output)."""
    for r in [l.split(',') for l in open(csv).read().split()[1:]]:
        m, dd, he, out = int(r[0]), int(r[1]), int(r[2]), float(r[3])
        t = 3600.0 * (he - 1)
        if 8 * 3600 <= t < (8 + occupied_h) * 3600:
            yield m, dd, t, out
