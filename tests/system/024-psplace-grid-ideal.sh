#!/bin/sh
# SPDX-License-Identifier: ISC
# psplace's ideal photocell on a grid's minimum or percentile, point by
# point: the over-lighting hours (output more than 0.01 above the ideal's)
# and the over-dimming hours (output more than 0.01 below it while the
# task is below the target) against the smallest output at which the
# figure of the points' daylight plus the output x their electric light
# reaches the target, not the figure of the daylight topped up with the
# figure of the electric light.  Grids whose points are the fixture's first
# point scaled by powers of two (each point's daylight that scale x the
# first's, exactly), with electric light that puts the darkest electric
# point elsewhere than the darkest daylit one; the four-point grid has a
# point without electric light (it reaches the target at any output when
# its daylight does, at none when not).  An independent computation
# (python, from the results and the year CSV psplace writes: the daylight
# figure per hour, interpolated between the hours as the room does, the
# output per hour with an instant ballast, one step an hour) must give
# psplace's hours, and the figure route must not (the cases tell them
# apart).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
command -v python3 > /dev/null || skip_all "no python3"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
mkdir -p "$TMP/poses"
tar -xzf "$D/p01.tar.gz" -C "$TMP/poses"
head -n 1 "$D/candidates.txt" > "$TMP/cands.txt"
python3 - "$D/grid_mf1.mtx" "$TMP" <<'EOF'
import sys
lines = open(sys.argv[1]).read().split('\n')
blank = lines.index('')
row = [float(x) for x in lines[blank + 1].split()]
for name, scale, elec in (('grid3', (1.0, 0.5, 2.0), (4.0, 6.0, 3.2)),
                          ('grid4', (1.0, 0.5, 2.0, 0.25), (4.0, 6.0, 3.2, 0.0))):
    head = [l if not l.startswith('NROWS=') else 'NROWS=%d' % len(scale) for l in lines[:blank]]
    with open('%s/%s.mtx' % (sys.argv[2], name), 'w') as f:
        f.write('\n'.join(head) + '\n\n')
        for a in scale:
            f.write('\t'.join(repr(a * x) for x in row) + '\n')
    with open('%s/%s.dat' % (sys.argv[2], name), 'w') as f:
        for x in elec:
            f.write('%g\t%g\t%g\n' % (x, x, x))
EOF
sed 's/^fade_rate = .*/fade_rate = 0/; s/^lag_tau = .*/lag_tau = 0/' "$TOP/config/psensd.conf" > "$TMP/psensd.conf"
for case in grid3:min grid4:p50 grid4:p75; do
	g=${case%%:*} fig=${case#*:}
	"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/cands.txt" -d "$TMP/poses" -g "$TMP/$g.mtx" -e "$TMP/$g.dat" \
		-w "$W" -s builtin:cosine -r 360 -a setpoint -p 3600 -T 0 -t $fig -o "$TMP/$fig.json" \
		-x "$TMP/$fig.results" -y "$TMP/$fig.csv" > "$TMP/$fig.out" 2> "$TMP/err"
	check "psplace -g $g -t $fig runs" test $? = 0
	PYTHONPATH="$TOP/tests/system" python3 - "$g" "$fig" "$TMP/$fig.json" "$TMP/$fig.results" "$TMP/$fig.csv" \
		> "$TMP/$fig.cmp" 2>&1 <<'EOF'
import json, math, sys
from roomgrid import elec_lux, year_hours, daylight, occupied_hours
g, fig, js, res, csv = sys.argv[1:]
d = json.load(open(js)); c = d['combinations'][0]
target, lo = d['target_lux'], 0.1   # the zone's min_level
scale = (1.0, 0.5, 2.0) if g == 'grid3' else (1.0, 0.5, 2.0, 0.25)
elec = elec_lux((4.0, 6.0, 3.2) if g == 'grid3' else (4.0, 6.0, 3.2, 0.0))
n = len(scale)
rank = 0 if fig == 'min' else max(0, min(n - 1, math.ceil(int(fig[1:]) / 100.0 * n) - 1))
def figure(v):
    return sorted(v)[rank]
def clamp(v):
    return min(1.0, max(lo, v))
hours = year_hours(res, figure(scale))
def ideal(D):
    # each point reaches the target from its threshold on; the figure of
    # rank r does when n - r points do
    th = []
    for a, e in zip(scale, elec):
        if e > 0:
            th.append((target - a * D) / e)
        else:
            th.append(-math.inf if a * D >= target else math.inf)
    return clamp(sorted(th)[n - 1 - rank])
over = {'exact': 0, 'figure': 0}
dim = {'exact': 0, 'figure': 0}
for m, dd, t, out in occupied_hours(csv, c['occupied_h'] / 365.0):
    D = daylight(hours, (m, dd), t)
    Dt = daylight(hours, (m, dd), t + 1e-3)
    truth = figure([a * Dt + out * e for a, e in zip(scale, elec)])
    want = {'exact': ideal(D), 'figure': clamp((target - figure(scale) * D) / figure(elec))}
    for k in want:
        over[k] += out > want[k] + 0.01
        dim[k] += out < want[k] - 0.01 and truth < target
print('%s -t %s: psplace over %.0f h, over-dimmed %.0f h; point by point %d h, %d h; the figures %d h, %d h'
      % (g, fig, c['over_h'], c['overdim_h'], over['exact'], dim['exact'], over['figure'], dim['figure']))
ok = (c['over_h'] == over['exact'] and c['overdim_h'] == dim['exact']
      and (over['figure'], dim['figure']) != (over['exact'], dim['exact']))
sys.exit(not ok)
EOF
	check "-g $g -t $fig: the ideal photocell point by point ($(tail -n 1 "$TMP/$fig.cmp"))" test $? = 0
done
done_testing
