#!/bin/sh
# SPDX-License-Identifier: ISC
# psscene on the example scene against the fixtures' Radiance reference
# integrals (0.1 %), the cache, missing and optional pictures, and rendering
# with a stand-in rpict that records its argument vector.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psscene" ] || skip_all "psscene not built"
within() { awk -v g="$1" -v r="$2" -v t="$3" 'BEGIN { d = (g - r) / r; if (d < 0) d = -d; exit !(d <= t) }'; }
val() { sed -n "/^\[condition $2\]/,/^\[/s/^$3 = //p" "$1" | head -n 1; }

"$BIN/psscene" -C "$TMP/cache" -o "$TMP/ofb.results" config/example/ofb.scene > "$TMP/out1" 2>&1
check "psscene runs on the example" test -s "$TMP/ofb.results"
# sensor W/m2 and task lux from the fixtures' README (Radiance-computed)
while read -r cond sensor task; do
	s=$(val "$TMP/ofb.results" "$cond" sensor_response)
	t=$(val "$TMP/ofb.results" "$cond" task_irradiance)
	check "$cond sensor $s W/m2 within 0.1 % of $sensor" within "$s" "$sensor" 1e-3
	check "$cond task $t W/m2 within 0.1 % of $task" within "$t" "$task" 1e-3
done <<'REF'
day_0318 5.069840 6.690722
day_0416 5.306592 7.001956
day_0517 5.462379 7.200648
elec 1.094120 7.069455
REF
check "the paper's Table 2 is printed beside ours" grep -q "paper measured" "$TMP/out1"
check "first run computes all 8" grep -q "8 integrations: 8 computed, 0 reused" "$TMP/out1"
"$BIN/psscene" -C "$TMP/cache" -o "$TMP/ofb.results" config/example/ofb.scene > "$TMP/out2" 2>&1
check "second run reuses all 8" grep -q "8 integrations: 0 computed, 8 reused" "$TMP/out2"
# change one input: only what depends on it is recomputed
mkdir -p "$TMP/scene/ofb"
cp -R config/example/ofb/img config/example/ofb/sensors config/example/ofb/dc config/example/ofb/weather "$TMP/scene/ofb/"
cp config/example/ofb.scene "$TMP/scene/"
"$BIN/psscene" -C "$TMP/cache" -o "$TMP/s.results" "$TMP/scene/ofb.scene" > /dev/null 2>&1
cp config/example/ofb/img/day_0416_task_256.hdr "$TMP/scene/ofb/img/day_0318_task_256.hdr"
"$BIN/psscene" -C "$TMP/cache" -o "$TMP/s.results" "$TMP/scene/ofb.scene" > "$TMP/out3" 2>&1
check "a changed picture already in the cache is reused by content" grep -q "0 computed, 8 reused" "$TMP/out3"
printf 'x' >> "$TMP/scene/ofb/img/day_0517_task_256.hdr"
"$BIN/psscene" -C "$TMP/cache" -o "$TMP/s.results" "$TMP/scene/ofb.scene" > "$TMP/out4" 2>&1
check "one changed picture is recomputed alone" grep -q "1 computed, 7 reused" "$TMP/out4"
# a missing picture fails clearly, unless its condition is optional
rm "$TMP/scene/ofb/img/day_0416_sensor_256.hdr"
"$BIN/psscene" -N -o "$TMP/m.results" "$TMP/scene/ofb.scene" > /dev/null 2> "$TMP/err"
check "missing picture: exit 1 and a message naming it" \
	grep -q "condition day_0416: sensor picture .*day_0416_sensor_256.hdr is missing" "$TMP/err"
sed -i 's/^\[condition day_0416\]/[condition day_0416]\noptional = yes/' "$TMP/scene/ofb.scene"
"$BIN/psscene" -N -o "$TMP/m.results" "$TMP/scene/ofb.scene" > "$TMP/out5" 2>&1
check "optional condition left out" grep -q "day_0416: pictures missing; optional condition left out" "$TMP/out5"
check "results say it was not computed" test "$(val "$TMP/m.results" day_0416 computed)" = no
# bad scene files: every error, with file:line
printf '[sensor]\nrotation = x\n[condition a]\nkind = sunlight\n' > "$TMP/bad.scene"
"$BIN/psscene" -N "$TMP/bad.scene" 2> "$TMP/err" >/dev/null
check "bad rotation reported at line 2" grep -q "bad.scene:2: rotation: 'x' is not a number" "$TMP/err"
check "bad kind reported at line 4 in the same pass" grep -q "bad.scene:4: kind: 'sunlight' is not one of" "$TMP/err"
# rendering a missing picture with a stand-in rpict: argv, no shell
oct="$TMP/my scene;rm -rf x.oct"
: > "$oct"
cat > "$TMP/r.scene" <<EOS
[sensor]
sensitivity = builtin:cosine
position = 1 2 3
resolution = 8
render_options = -ab 2 -ad 64
[task]
position = 1 2 0.8
[condition night]
kind = electric
octree = $oct
sensor_picture = s.hdr
task_picture = t.hdr
EOS
PATH="$TOP/tests/system/bin:$PATH" RPICT_LOG="$TMP/argv" "$BIN/psscene" -N -o "$TMP/r.results" "$TMP/r.scene" > "$TMP/out6" 2>&1
check "rendered both pictures" grep -q "2 rendered" "$TMP/out6"
check "the octree path with a space and ';' arrived as one argument" grep -qxF "$oct" "$TMP/argv"
check "cosine sensor: -vta -vh 180" sh -c "head -n 40 '$TMP/argv' | tr '\n' ' ' | grep -q -- '-vta -vp 1 2 3 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180 -x 8 -y 8 -ab 2 -ad 64'"
check "uniform stand-in picture gives pi x 1.00390625 at the task" \
	within "$(val "$TMP/r.results" night task_irradiance)" 3.1538633 1e-6
# a narrow sensor gets a narrow view, one past 90 degrees a 360-degree one
printf 'Elevation field 30\ndegrees 0 90 180 270\n0 1 1 1 1\n30 1 1 1 1\n' > "$TMP/narrow.sen"
printf 'Elevation field 120\ndegrees 0 90 180 270\n0 1 1 1 1\n120 1 1 1 1\n' > "$TMP/wide.sen"
for s in narrow:60 wide:360; do
	name=${s%%:*}; want=${s##*:}
	sed "s|sensitivity = builtin:cosine|sensitivity = $name.sen|" "$TMP/r.scene" > "$TMP/$name.scene"
	rm -f "$TMP/s.hdr" "$TMP/t.hdr" "$TMP/argv"
	PATH="$TOP/tests/system/bin:$PATH" RPICT_LOG="$TMP/argv" "$BIN/psscene" -N -q -o "$TMP/n.results" "$TMP/$name.scene" 2>/dev/null
	check "$name sensor rendered with -vh $want" sh -c "head -n 40 '$TMP/argv' | tr '\n' ' ' | grep -q -- '-vh $want -vv $want'"
done
# without rpict: say what is missing and how to render it
rm -f "$TMP/s.hdr" "$TMP/t.hdr"
PATH=/usr/bin:/bin "$BIN/psscene" -N -o "$TMP/r.results" "$TMP/r.scene" > /dev/null 2> "$TMP/err"
check "no rpict: the command to render is given" grep -q "rpict (Radiance) is not on PATH; render it with: rpict -vta" "$TMP/err"
done_testing
