#!/bin/sh
# SPDX-License-Identifier: ISC
# psscene with daylight-coefficient picture sets: the example office's set
# integrates (uniform-sky sums from the fixture README), and a bad set (a
# missing patch, mixed sizes, a count no MF has) fails naming the file or
# patch with the results file left as it was.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psscene" ] || skip_all "psscene not built"

"$BIN/psscene" -N -o "$TMP/ofb.results" config/example/ofb.scene > "$TMP/out" 2>&1
check "the example's coefficient sets integrate" \
	grep -q "daylight coefficients: MF 1, 146 patches of 64 x 64" "$TMP/out"
# the fixture README's 64 x 64 sums (0.16146, 0.31943) within 1e-3
s=$(sed -n 's/.*sensor response \([0-9.]*\), task \([0-9.]*\) W.*/\1 \2/p' "$TMP/out")
check "uniform-sky sums $s match the fixture's" awk -v s="$s" 'BEGIN { split(s, a, " ");
	d1 = a[1] / 0.16146 - 1; d2 = a[2] / 0.31943 - 1; exit !(d1 * d1 < 1e-6 && d2 * d2 < 1e-6) }'

# a scene of its own with a copy of the set to break
mkdir -p "$TMP/s/dc/sensor" "$TMP/s/dc/task"
cp config/example/ofb/dc/sensor/*.hdr "$TMP/s/dc/sensor/"
cp config/example/ofb/dc/task/*.hdr "$TMP/s/dc/task/"
cat > "$TMP/s/dc.scene" <<'SCENE'
[sensor]
sensitivity = builtin:cosine
[daylight_coefficients]
mf = 1
sensor_pictures = dc/sensor/dc_%03d.hdr
sensor_view = -vta -vp 1.85 2.285 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180
task_pictures = dc/task/dc_%03d.hdr
task_view = -vta -vp 1.85 2.285 0.762 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180
SCENE
"$BIN/psscene" -N -o "$TMP/dc.results" "$TMP/s/dc.scene" > "$TMP/out" 2>&1
check "a scene of coefficient sets alone runs" test -s "$TMP/dc.results"
cp "$TMP/dc.results" "$TMP/dc.before"
bad() { # what, expected message
	if "$BIN/psscene" -N -o "$TMP/dc.results" "$TMP/s/dc.scene" > "$TMP/out" 2>&1; then
		check "$1 is refused" false
	else
		check "$1: '$2'" grep -qF "$2" "$TMP/out"
	fi
	check "$1: the results file is left as it was" cmp -s "$TMP/dc.results" "$TMP/dc.before"
	check "$1: no temporary file is left" sh -c "! ls '$TMP'/dc.results.tmp* 2>/dev/null"
}
mv "$TMP/s/dc/task/dc_077.hdr" "$TMP/s/keep.hdr"
bad "a missing patch" "patch 77 of 146 (MF 1) is missing: $TMP/s/dc/task/dc_077.hdr"
mv "$TMP/s/keep.hdr" "$TMP/s/dc/task/dc_077.hdr"
cp config/example/ofb/img/elec_sensor_256.hdr "$TMP/s/dc/sensor/dc_012.hdr"
bad "mixed sizes" "$TMP/s/dc/sensor/dc_012.hdr: patch 12 is 256 x 256, patch 0"
cp config/example/ofb/dc/sensor/dc_012.hdr "$TMP/s/dc/sensor/"
sed -i 's/^mf = 1/mf = 0/' "$TMP/s/dc.scene"
rm "$TMP"/s/dc/sensor/dc_14[0-5].hdr
bad "a count no MF has" "140 pictures (patches 0 to 139) match no MF"
sed -i 's/^sensor_view.*/sensor_view = -vtv -vp 1 1 1/' "$TMP/s/dc.scene"
bad "a view that is no fisheye" "dc.scene:6: sensor_view: view type -vtv is not a fisheye"
# the year: a bad weather line is named, the results file left alone
sed -i 's/^sensor_view.*/sensor_view = -vta -vp 1.85 2.285 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180/; s/^mf = 0/mf = 1/' "$TMP/s/dc.scene"
cp config/example/ofb/dc/sensor/dc_14[0-5].hdr "$TMP/s/dc/sensor/"
head -n 20 config/example/ofb/weather/sf-tmy3.wea > "$TMP/s/w.wea"
echo "1 1 14.5 -5 100" >> "$TMP/s/w.wea"
echo "weather = w.wea" >> "$TMP/s/dc.scene"
bad "a negative irradiance in the weather" "w.wea:21"
sed -i '$d' "$TMP/s/w.wea"
"$BIN/psscene" -N -o "$TMP/dc.results" "$TMP/s/dc.scene" > "$TMP/out" 2>&1
lit=$(awk 'NR > 6 && $4 + $5 > 0' "$TMP/s/w.wea" | wc -l)
check "a short year runs: 14 steps, $lit with light (the file's lines with light)" \
	grep -q "14 steps, $lit with light, $((14 - lit)) dark skipped" "$TMP/out"
check "the results carry them (version 2)" sh -c "grep -q '^version = 2' '$TMP/dc.results' && grep -q '^hours = $lit\$' '$TMP/dc.results'"
done_testing
