#!/bin/sh
# SPDX-License-Identifier: ISC
# check: long
# psplace renders the candidates' missing pictures with Radiance (-M, -K,
# -L) into the content-keyed cache.  CI has no Radiance: stand-ins for
# vwrays, rfluxmtx and rpict (radstub.py) check their command lines as
# Radiance's manual pages define them and answer with the placement
# fixture's pictures (tests/data/ofb-place: p01, p07, p09), so:
#   - rendered pictures give the scores the same pictures give unpacked
#     (-d): the plumbing loses nothing;
#   - only missing pictures are rendered: a rerun renders none, a removed
#     set is rendered again alone, two candidates with one view once;
#   - -J 2 runs two renderers at once, -J 1 one;
#   - poses on a ceiling grid (--ceiling, --aims) where the fixture's are
#     score as the fixture's;
#   - a failing renderer is reported naming the candidate and the command,
#     and leaves no partial picture in the cache; a receiver file with the
#     wrong patches is refused; without Radiance on PATH, a clear error.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
command -v python3 > /dev/null || skip_all "python3 missing"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
mkdir -p "$TMP/src" "$TMP/bin" "$TMP/log" "$TMP/none"
for p in p01 p07 p09; do tar -xzf "$D/$p.tar.gz" -C "$TMP/src"; done
for t in vwrays rfluxmtx rpict; do ln -s "$TOP/tests/system/radstub.py" "$TMP/bin/$t"; done
echo "stand-in octree, lamps off" > "$TMP/day.oct"
echo "stand-in octree, lamps on" > "$TMP/lamps.oct"
cp "$TOP/config/example/ofb/dc/skydome.rad" "$TMP/skydome.rad"
sed "s|^database = .*|database = $TMP/psensd.db|; s|^scene = .*|scene = $TOP/config/example/ofb.scene|" \
	"$TOP/config/psensd.conf" > "$TMP/psensd.conf"
export STUB_SRC="$TMP/src" STUB_CANDS="$D/candidates.txt" STUB_LOG="$TMP/log" STUB_SLEEP=0.5
place() {
	PATH="$TMP/bin:$PATH" "$BIN/psplace" -f "$TMP/psensd.conf" -c "$D/candidates.txt" -g "$D/grid_mf1.mtx" \
		-e "$D/grid_elec.dat" -w "$W" -r 120 -a setpoint -a switching -T 0 -q "$@"
}
render() { place -d "$TMP/none" -M "$TMP/day.oct" -K "$TMP/skydome.rad" -L "$TMP/lamps.oct" "$@"; }
calls() { grep -c "^$1 " "$TMP/log/calls" 2> /dev/null || true; }
energies() { python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
for c in sorted(d['combinations'], key=lambda c: (c['pose'], c['rotation'], c['law'])):
    print(c['pose'], c['rotation'], c['law'], repr(c['energy_h']), repr(c['below90_h']))" "$1"; }

place -d "$TMP/src" -o "$TMP/ref.json" > /dev/null 2> "$TMP/err"
check "the reference run on the unpacked pictures" test $? = 0

render -C "$TMP/cache" -J 2 -o "$TMP/r1.json" > /dev/null 2> "$TMP/err"
check "psplace renders the pictures ($(tail -n 1 "$TMP/err"))" test $? = 0
check "three coefficient sets and three electric pictures rendered" \
	grep -q "rendered 3 coefficient set(s) and 3 electric picture(s) with 2 job(s); 0 and 0 from the cache" "$TMP/err"
check "rfluxmtx ran three times, rpict three times" test "$(calls rfluxmtx)/$(calls rpict)" = 3/3
check "each pose rendered once (p01 p07 p09)" test "$(awk '{ print $2 }' "$TMP/log/calls" | sort | uniq -c |
	awk '{ printf "%s%s", $1, $2 }')" = "2p012p072p09"
check "two renderers at once with -J 2" awk '$3 >= 2 { n++ } END { exit !n }' "$TMP/log/calls"
energies "$TMP/ref.json" > "$TMP/ref.txt"
energies "$TMP/r1.json" > "$TMP/r1.txt"
check "rendered pictures score as the unpacked ones ($(wc -l < "$TMP/ref.txt") combinations)" \
	sh -c "test -s '$TMP/ref.txt' && cmp -s '$TMP/ref.txt' '$TMP/r1.txt'"
check "the cache holds three sets of 146 and three electric pictures" test \
	"$(ls -d "$TMP"/cache/pictures/dc-* | wc -l)/$(cat "$TMP"/cache/pictures/dc-*/dc_*.hdr | wc -c | awk '$1 > 0 { print "x" }')/$(ls "$TMP"/cache/pictures/dc-*/ | grep -c '^dc_')/$(ls "$TMP"/cache/pictures/elec-*.hdr | wc -l)" = "3/x/438/3"

rm -f "$TMP/log/calls"
render -C "$TMP/cache" -o "$TMP/r2.json" > /dev/null 2> "$TMP/err"
check "a rerun renders nothing" sh -c "grep -q 'rendered 0 coefficient set(s) and 0 electric picture(s)' '$TMP/err' &&
	test ! -s '$TMP/log/calls'"
energies "$TMP/r2.json" > "$TMP/r2.txt"
check "and scores the same" cmp -s "$TMP/ref.txt" "$TMP/r2.txt"
rm -r "$(ls -d "$TMP"/cache/pictures/dc-* | head -n 1)"
render -C "$TMP/cache" > /dev/null 2> "$TMP/err"
check "a removed set is rendered again, alone" sh -c "grep -q 'rendered 1 coefficient set(s) and 0 electric' '$TMP/err' &&
	test \"\$(grep -c . '$TMP/log/calls')\" = 1"
rm -f "$TMP/log/calls"
render -C "$TMP/cache" --dc-options "-ab 4 -ad 1024 -lw 1e-4" > /dev/null 2> "$TMP/err"
check "a changed rfluxmtx option renders the sets again, not the electric pictures" \
	test "$(calls rfluxmtx)/$(calls rpict)" = 3/0

rm -f "$TMP/log/calls"
render -C "$TMP/cache1" -J 1 > /dev/null 2> "$TMP/err"
check "-J 1: six renders, one at a time" sh -c "test \"$(calls rfluxmtx)/$(calls rpict)\" = 3/3 &&
	awk '\$3 != 1 { bad = 1 } END { exit bad }' '$TMP/log/calls'"

# candidates on a ceiling grid with their aims, rendered: two points facing
# down where p01 and p07 are, and the room's centre tilted 45 degrees toward
# the window (azimuth 180: -y) where p09 is, score as those poses
rm -f "$TMP/log/calls"
PATH="$TMP/bin:$PATH" "$BIN/psplace" -f "$TMP/psensd.conf" --ceiling 1.85,1.85,1,0.8,3.8,2,2.2 \
	-g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" -w "$W" -r 120 -a setpoint -a switching -T 0 -q -d "$TMP/none" \
	-M "$TMP/day.oct" -K "$TMP/skydome.rad" -L "$TMP/lamps.oct" -C "$TMP/cache" -o "$TMP/g.json" > /dev/null 2> "$TMP/err"
check "a ceiling grid facing down: rendered from the cache ($(tail -n 1 "$TMP/err"))" \
	grep -q "rendered 0 coefficient set(s) and 0 electric picture(s) with .* 2 and 2 from the cache" "$TMP/err"
PATH="$TMP/bin:$PATH" "$BIN/psplace" -f "$TMP/psensd.conf" --ceiling 1.85,1.85,1,2.285,2.285,1,2.2 --aims 45@180 \
	-g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" -w "$W" -r 120 -a setpoint -a switching -T 0 -q -d "$TMP/none" \
	-M "$TMP/day.oct" -K "$TMP/skydome.rad" -L "$TMP/lamps.oct" -C "$TMP/cache" -o "$TMP/t.json" > /dev/null 2> "$TMP/err"
check "a tilted aim runs" test $? = 0
{ energies "$TMP/g.json" | sed 's/^g00 /p01 /; s/^g01 /p07 /'; energies "$TMP/t.json" | sed 's/^g00 /p09 /'; } |
	sort > "$TMP/g.txt"
sort "$TMP/ref.txt" > "$TMP/refs.txt"
check "the grid's poses score as p01, p07 and p09 ($(wc -l < "$TMP/g.txt") combinations)" cmp -s "$TMP/refs.txt" "$TMP/g.txt"
"$BIN/psplace" -f "$TMP/psensd.conf" --ceiling 1,2,3 -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" -w "$W" \
	> /dev/null 2> "$TMP/err"
check "a bad ceiling grid refused" grep -q "\-\-ceiling 1,2,3: expected X0,X1,NX,Y0,Y1,NY,Z" "$TMP/err"
"$BIN/psplace" -f "$TMP/psensd.conf" --ceiling 1,2,2,1,2,2,2.2 --aims down,95@0 -g "$D/grid_mf1.mtx" \
	-e "$D/grid_elec.dat" -w "$W" > /dev/null 2> "$TMP/err"
check "a bad aim refused" grep -q "tilt '95' is not 0 to below 90 degrees" "$TMP/err"

# two candidates with the same view: rendered once
{ cat "$D/candidates.txt"; sed -n 's/^p07 /again /p' "$D/candidates.txt"; } > "$TMP/twice.txt"
rm -f "$TMP/log/calls"
PATH="$TMP/bin:$PATH" "$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/twice.txt" -g "$D/grid_mf1.mtx" \
	-e "$D/grid_elec.dat" -w "$W" -r 360 -a setpoint -T 0 -q -d "$TMP/none" -M "$TMP/day.oct" -K "$TMP/skydome.rad" \
	-L "$TMP/lamps.oct" -C "$TMP/cache6" -J 4 > /dev/null 2> "$TMP/err"
check "two candidates with one view: each picture rendered once" sh -c "grep -q 'rendered 3 coefficient set(s) and 3 electric' '$TMP/err' &&
	test \"$(calls rfluxmtx)/$(calls rpict)\" = 3/3"

# failures
STUB_FAIL=p07 render -C "$TMP/cache2" -J 2 > /dev/null 2> "$TMP/err"
check "a failing rfluxmtx is an error" test $? -ne 0
check "naming the candidate and the command ($(head -c 160 "$TMP/err" | tail -n 1))" grep -q \
	"psplace: candidate p07: coefficient pictures: rfluxmtx exited with status 1: .*vwrays -ff -vta -vp 1.85 3.8.*| .*rfluxmtx -ffc -x 64 -y 64 -ld- -ab 3 -ad 1024 -lw 1e-4 -o .* - $TMP/skydome.rad -i $TMP/day.oct" "$TMP/err"
check "no partial set in the cache" sh -c "! ls '$TMP/cache2/pictures' | grep -q tmp &&
	for d in '$TMP'/cache2/pictures/dc-*; do [ ! -e \"\$d\" ] || [ \$(ls \"\$d\" | wc -l) = 146 ] || exit 1; done"
STUB_FAIL=p09 STUB_FAIL_PROG=rpict render -C "$TMP/cache3" -J 2 > /dev/null 2> "$TMP/err"
check "a failing rpict is an error naming the candidate and the command" grep -q \
	"psplace: candidate p09: electric picture: .*rpict exited with status 1: .*rpict -vta -vp 1.85[0-9]* 2.28[0-9]* 2.2[0-9]* .* -x 128 -y 128 -ab 3 .* $TMP/lamps.oct" "$TMP/err"
check "no partial electric picture in the cache" sh -c "test \$(ls '$TMP/cache3/pictures' | grep -c '^elec-') -le 2 &&
	! ls '$TMP/cache3/pictures' | grep -q rendering"
grep -v "h=r1" "$TMP/skydome.rad" > "$TMP/ground.rad"
place -d "$TMP/none" -M "$TMP/day.oct" -K "$TMP/ground.rad" -C "$TMP/cache4" > /dev/null 2> "$TMP/err"
check "a receiver with the wrong patches refused" grep -q "candidate p0[179]: coefficient pictures: rfluxmtx did not write exactly the grid's 146 patch pictures" "$TMP/err"
check "and nothing left in the cache" test -z "$(ls "$TMP/cache4/pictures")"
PATH="$TMP/none" "$BIN/psplace" -f "$TMP/psensd.conf" -c "$D/candidates.txt" -g "$D/grid_mf1.mtx" \
	-e "$D/grid_elec.dat" -w "$W" -r 360 -d "$TMP/none" -M "$TMP/day.oct" -K "$TMP/skydome.rad" -C "$TMP/cache5" \
	> /dev/null 2> "$TMP/err"
check "without Radiance: a clear error" grep -q "vwrays (Radiance) is not on PATH" "$TMP/err"
place -d "$TMP/none" -M "$TMP/day.oct" -C "$TMP/cache5" > /dev/null 2> "$TMP/err"
check "-M without -K refused" grep -q "needs the sky patches' receiver file (-K)" "$TMP/err"
done_testing
