#!/bin/sh
# SPDX-License-Identifier: ISC
# psplace's scores against a brute-force psensd -Y for several candidates,
# not only one: for each of three poses of the placement fixture (a
# ceiling point facing down, two tilted) with a sensor whose sensitivity
# depends on azimuth, psplace searches four rotations and writes its
# winner's results (-x); psensd -Y runs the year on them through its own
# route (the full room at every step, no hook, no lean steps) and its
# energy %, savings %, hours below 90 %, over-dimming hours and changes an
# hour of all five laws must be psplace's to psensd's printed digits.
# psplace runs the years at 10-minute steps here (the rows' signals in
# blocks, the unoccupied steps lean); psensd at the same period.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "no python3"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
mkdir -p "$TMP/poses"
for p in p01 p07 p09; do tar -xzf "$D/$p.tar.gz" -C "$TMP/poses"; done
awk 'BEGIN { printf "Elevation field 90\ndegrees\t0\t90\t180\t270\n";
	for (t = 0; t <= 90; t += 10) { c = cos(t * 3.14159265358979 / 180); if (t == 90) c = 0;
		printf "%d\t%.6f\t%.6f\t%.6f\t%.6f\n", t, 1.9 * c, c, 0.1 * c, c } }' > "$TMP/lopsided.sen"
sed "s|^database = .*|database = $TMP/psensd.db|; s|^scene = .*|scene = $TOP/config/example/ofb.scene|; s|^results = .*|results = $TMP/best.results|; s|^period = .*|period = 600|" \
	"$TOP/config/psensd.conf" > "$TMP/psensd.conf"
for p in p01 p07 p09; do
	grep "^$p " "$D/candidates.txt" > "$TMP/c-$p.txt"
	"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/c-$p.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
		-w "$W" -s "$TMP/lopsided.sen" -r 90 -T 0 -o "$TMP/$p.json" -x "$TMP/best.results" > "$TMP/$p.out" 2> "$TMP/err"
	check "psplace on $p runs" test $? = 0
	"$BIN/psensd" -f "$TMP/psensd.conf" -Y > "$TMP/$p.year" 2> "$TMP/year.err"
	check "psensd -Y on $p's winner runs" test $? = 0
	python3 - "$TMP/$p.json" "$TMP/$p.year" > "$TMP/$p.cmp" 2>&1 <<'EOF'
import json, re, sys
d = json.load(open(sys.argv[1]))
best = d['combinations'][0]
mine = {c['law']: c for c in d['combinations']
        if c['pose'] == best['pose'] and c['rotation'] == best['rotation'] and c['sensor'] == best['sensor']}
bad = seen = 0
for line in open(sys.argv[2]):
    m = re.match(r'^  (setpoint|closed-proportional|open-proportional|integral-reset|switching) +'
                 r'([0-9.]+) +([0-9.]+) +\S+ +\S+ +([0-9.]+) +([0-9.]+) +([0-9.]+)$', line)
    if not m:
        continue
    c = mine[m.group(1)]
    want = ['%.1f' % c['energy_pct'], '%.1f' % c['savings_pct'], '%.1f' % c['below90_h'],
            '%.1f' % c['overdim_h'], '%.2f' % c['changes_per_h']]
    got = [m.group(i) for i in (2, 3, 4, 5, 6)]
    seen += 1
    if want != got:
        bad += 1
        print('law %s: psplace %s, psensd -Y %s' % (m.group(1), want, got))
print('%s rotated %g: %d laws compared, %d differ' % (best['pose'], best['rotation'], seen, bad))
sys.exit(bad != 0 or seen != 5)
EOF
	check "$p: the five laws' scores are psensd -Y's ($(tail -n 1 "$TMP/$p.cmp"))" test $? = 0
done
check "the period was 600 s" grep -q '"period_s": *600' "$TMP/p01.json"
done_testing
