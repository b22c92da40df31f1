#!/bin/sh
# SPDX-License-Identifier: ISC
# psplace over a subset of the placement fixture (tests/data/ofb-place:
# three poses, the 20-point grid) and the example office's own sensor set:
#   - its scores against a brute-force psensd -Y on the results psplace
#     writes for the winner: energy %, hours below 90 %, over-dimming hours
#     and changes an hour of all five laws agree to psensd's printed digits
#     (psensd prints one decimal, two for changes an hour);
#   - rotations by the projection route against the exact integration, for
#     a sensor whose sensitivity depends on azimuth at four rotations: the
#     year's sensor signal within 0.5 % and the energy within 0.05 points
#     (the projection's cells are 2 x 10 degrees on 64 x 64 pictures;
#     measured up to 0.14 % and 0.001 points);
#   - an asymmetric sensor gives different rotations different signals, a
#     cosine sensor the same;
#   - the plan of the poses is a PNG;
#   - the schedule: 8760 hourly power fractions in [0, 1] whose sum over the
#     occupied hours is the year's energy (an independent summation);
#   - a candidate with a missing patch or a mismatched picture, a grid with
#     a point too few, a NaN in the matrix, an unknown figure: refused,
#     naming the candidate or the file and line.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
mkdir -p "$TMP/poses"
for p in p01 p07 p09; do tar -xzf "$D/$p.tar.gz" -C "$TMP/poses"; done
# the example's own set at p04 (config/example/ofb/dc/sensor, 64 x 64 MF 1)
mkdir -p "$TMP/poses/ex"
for f in "$TOP"/config/example/ofb/dc/sensor/dc_*.hdr; do ln -s "$f" "$TMP/poses/ex/"; done
ln -s "$TOP/config/example/ofb/img/elec_sensor_256.hdr" "$TMP/poses/ex/elec.hdr"
{ cat "$D/candidates.txt"; echo "ex -vta -vp 1.85 2.285 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180"; } > "$TMP/cands.txt"
# a sensor that sees more towards its azimuth 0: cos(theta) (1 + 0.9 cos(phi))
awk 'BEGIN { printf "Elevation field 90\ndegrees\t0\t90\t180\t270\n";
	for (t = 0; t <= 90; t += 10) { c = cos(t * 3.14159265358979 / 180); if (t == 90) c = 0;
		printf "%d\t%.6f\t%.6f\t%.6f\t%.6f\n", t, 1.9 * c, c, 0.1 * c, c } }' > "$TMP/lopsided.sen"
sed "s|^database = .*|database = $TMP/psensd.db|; s|^scene = .*|scene = $TOP/config/example/ofb.scene|; s|^results = .*|results = $TMP/best.results|" \
	"$TOP/config/psensd.conf" > "$TMP/psensd.conf"

"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/cands.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
	-w "$W" -s builtin:cosine -s "$TMP/lopsided.sen" -r 90 -T 4 -o "$TMP/out.json" -x "$TMP/best.results" \
	-E "$TMP/sched.csv" -y "$TMP/year.csv" -Z "$TMP/zone.conf" -P "$TMP/plan.png" > "$TMP/out" 2> "$TMP/err"
check "psplace runs" test $? = 0
check "4 poses x 4 rotations x 2 sensors x 5 laws = 160 combinations" grep -q "= 160 combinations" "$TMP/out"
check "a ranked table" grep -qE "^   1 (p01|p07|p09|ex) " "$TMP/out"
check "the JSON holds 160 combinations" python3 -c "
import json, sys; d = json.load(open('$TMP/out.json')); sys.exit(len(d['combinations']) != 160)"

# the brute force: psensd -Y on the winner's results
"$BIN/psensd" -f "$TMP/psensd.conf" -Y > "$TMP/year.out" 2> "$TMP/year.err"
check "psensd -Y runs on psplace's results" test $? = 0
python3 - "$TMP/out.json" "$TMP/year.out" > "$TMP/cmp" 2>&1 <<'EOF'
import json, re, sys
d = json.load(open(sys.argv[1]))
best = d['combinations'][0]
mine = {c['law']: c for c in d['combinations']
        if c['pose'] == best['pose'] and c['rotation'] == best['rotation'] and c['sensor'] == best['sensor']}
bad = 0
seen = 0
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
print('%d laws compared, %d differ' % (seen, bad))
sys.exit(bad != 0 or seen != 5)
EOF
check "the five laws' scores are psensd -Y's ($(tail -n 1 "$TMP/cmp"))" test $? = 0
[ -s "$TMP/cmp" ] && sed 's/^/# /' "$TMP/cmp"

# rotations: projection against the exact route, the lopsided sensor at all
# four rotations of the tilted pose (the best four of that search)
echo "p09 $(sed -n 's/^p09 //p' "$D/candidates.txt")" > "$TMP/c-p09.txt"
"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/c-p09.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
	-w "$W" -s "$TMP/lopsided.sen" -a setpoint -r 90 -T 4 > "$TMP/rot.out" 2> "$TMP/err"
n=$(grep -c "^exact route, rank" "$TMP/rot.out")
check "four rotations re-checked by the exact route" test "$n" = 4
check "the projection's sensor signal within 0.5 % of the exact route's" awk '
	/^exact route, rank/ { s = $10; sub(/%/, "", s); if (s < 0) s = -s; if (s + 0 >= 0.5) bad = 1; n++ }
	END { exit bad || !n }' "$TMP/rot.out"
check "the energy within 0.05 points" awk '
	/^exact route, rank/ { e = $(NF - 1); if (e < 0) e = -e; if (e + 0 >= 0.05) bad = 1; n++ }
	END { exit bad || !n }' "$TMP/rot.out"
grep "^exact route" "$TMP/rot.out" | sed 's/^/# /'
check "the lopsided sensor's rotations differ, the cosine's do not" python3 -c "
import json, sys
d = json.load(open('$TMP/out.json'))
def energies(sensor):
    return {c['rotation']: c['energy_h'] for c in d['combinations']
            if c['pose'] == 'p09' and c['law'] == 'setpoint' and c['sensor'] == sensor}
lop = energies('$TMP/lopsided.sen'); cos = energies('builtin:cosine')
sys.exit(not (len(set(lop.values())) > 1 and max(cos.values()) - min(cos.values()) < 1e-3 * max(cos.values())))"

# the schedule against the year's energy
check "the schedule: a header and 8760 hours" test "$(wc -l < "$TMP/sched.csv")" = 8761
check "the year CSV: a header and 8760 hours" test "$(wc -l < "$TMP/year.csv")" = 8761
check "fractions in [0, 1], occupied hours summing to the year's energy" python3 -c "
import json, sys
d = json.load(open('$TMP/out.json')); best = d['combinations'][0]
rows = [l.split(',') for l in open('$TMP/year.csv').read().split()[1:]]
p = [float(r[4]) for r in rows]
occ = sum(float(r[4]) for r in rows if 9 <= int(r[2]) <= 18)
sys.exit(not (min(p) >= 0 and max(p) <= 1 and abs(occ - best['energy_h']) < 0.01))"
check "the plan drawn as a PNG" sh -c "head -c 8 '$TMP/plan.png' | od -An -c | grep -q 'P   N   G'"
check "the zone section names the law" grep -qE "^algorithm = (setpoint|closed-proportional|open-proportional|integral-reset|switching)$" "$TMP/zone.conf"

# refusals
run() { "$BIN/psplace" -f "$TMP/psensd.conf" -w "$W" -r 360 -T 0 "$@" > /dev/null 2> "$TMP/err"; }
cp -r "$TMP/poses/p07" "$TMP/poses/p07m"
rm "$TMP/poses/p07m/dc_050.hdr"
echo "p07m -vta -vp 1.85 3.80 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180" > "$TMP/c-missing.txt"
run -c "$TMP/c-missing.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat"
check "a missing patch refused" test $? -ne 0
check "naming the candidate and the patch" grep -q "candidate p07m: patch 50 of 146" "$TMP/err"
cp "$TOP/config/example/ofb/img/day_0318_sensor_256.hdr" "$TMP/poses/p07m/dc_050.hdr"
run -c "$TMP/c-missing.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat"
check "a mismatched picture refused" grep -q "candidate p07m: .*dc_050.hdr is 256 x 256 where dc_000.hdr is 64 x 64" "$TMP/err"
head -n 19 "$D/grid_elec.dat" > "$TMP/elec19.dat"
run -c "$D/candidates.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$TMP/elec19.dat"
check "a grid's electric file a point short refused, naming file and line" grep -q "elec19.dat:19: 19 points where the grid has 20" "$TMP/err"
awk 'NR == 14 { $5 = "nan" } { print }' "$D/grid_mf1.mtx" > "$TMP/nan.mtx"
run -c "$D/candidates.txt" -d "$TMP/poses" -g "$TMP/nan.mtx" -e "$D/grid_elec.dat"
check "a NaN in the matrix refused, naming file and line" grep -q "nan.mtx:14: NaN" "$TMP/err"
run -c "$D/candidates.txt" -d "$TMP/poses" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" -t p200
check "an unknown grid figure refused" grep -q "\-t p200" "$TMP/err"
done_testing
