#!/bin/sh
# SPDX-License-Identifier: ISC
# psplace -F: the best combination's sensor sensitivity, at its rotation,
# over its pose's fisheye (pose p01 of tests/data/ofb-place, facing down,
# -vta -vh 180, its 128 x 128 electric picture drawn 4 times larger 39
# pixels in: the axis at canvas (295, 295), 90 degrees off it 256 pixels
# away; azimuth 0 up, growing to the left as psens counts it).  Pixels
# where the answer is known (tests/system/pngcolours.py --at):
#   - a cosine sensor tints the whole hemisphere: near the axis (8 degrees,
#     0.99 of its peak) the scale's top (red), at 75 degrees (0.26) blue;
#   - a cone sensor (1 to 30 degrees, 0 past 50) tints near its axis the
#     same red, and leaves the picture grey at 75 degrees, outside its field;
#   - outside the fisheye, the background;
#   - a lopsided sensor (1.9 cos at its azimuth 0, 0.1 cos at 180) drawn at
#     the rotation psplace chose: at 45 degrees off the axis, 15 degrees from
#     the sensor's azimuth 0 it is 0.65 of its peak, from 195 degrees 0.09:
#     the first warm, the second blue, wherever the rotation put them.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
PC="python3 $TOP/tests/system/pngcolours.py --at"
tar -xzf "$D/p01.tar.gz" -C "$TMP"
grep "^p01 " "$D/candidates.txt" > "$TMP/c.txt"
sed "s|^database = .*|database = $TMP/psensd.db|; s|^scene = .*|scene = $TOP/config/example/ofb.scene|" \
	"$TOP/config/psensd.conf" > "$TMP/psensd.conf"
awk 'BEGIN { printf "Elevation field 90\ndegrees\t0\t90\t180\t270\n";
	for (t = 0; t <= 90; t += 10) { c = cos(t * 3.14159265358979 / 180); if (t == 90) c = 0;
		printf "%d\t%.6f\t%.6f\t%.6f\t%.6f\n", t, 1.9 * c, c, 0.1 * c, c } }' > "$TMP/lopsided.sen"
place() {
	"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/c.txt" -d "$TMP" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
		-w "$W" -a setpoint -T 0 -q "$@" > /dev/null 2> "$TMP/err"
}
# r, g, b of one pixel
px() { $PC "$1" "$2" | tail -n 1; }
red() { echo "$1" | awk -F, '{ exit !($1 > $2 + 60 && $1 > $3 + 60) }'; }
blue() { echo "$1" | awk -F, '{ exit !($3 > $1 + 40 && $3 > $2 + 20) }'; }
grey() { echo "$1" | awk -F, '{ exit !($1 == $2 && $2 == $3) }'; }
warm() { echo "$1" | awk -F, '{ exit !($1 + $2 > 2 * $3 + 60) }'; }

place -r 360 -s builtin:cosine -F "$TMP/cos.png"
check "psplace -F writes a PNG" sh -c "head -c 8 '$TMP/cos.png' | od -An -c | grep -q 'P   N   G'"
a=$(px "$TMP/cos.png" 311,311); b=$(px "$TMP/cos.png" 446,446); o=$(px "$TMP/cos.png" 5,5)
check "cosine, 8 degrees off the axis: the scale's top ($a)" red "$a"
check "cosine, 75 degrees: tinted blue ($b)" blue "$b"
check "outside the fisheye: the background ($o)" test "$o" = "28,28,28"
place -r 360 -s "$TOP/config/example/ofb/sensors/cone.sen" -F "$TMP/cone.png"
a=$(px "$TMP/cone.png" 311,311); b=$(px "$TMP/cone.png" 446,446)
check "cone, 8 degrees off the axis: the scale's top ($a)" red "$a"
check "cone, 75 degrees, outside its field: the picture in grey ($b)" grey "$b"

place -r 180 -s "$TMP/lopsided.sen" -F "$TMP/lop.png" -o "$TMP/lop.json"
rot=$(python3 -c "import json; print(int(json.load(open('$TMP/lop.json'))['combinations'][0]['rotation']))")
# canvas offsets of (theta 45, azimuth phi): 128 pixels out, phi growing to the left of up
at() { awk -v p="$1" 'BEGIN { p = p * 3.14159265358979 / 180;
	printf "%d,%d\n", 295 - 128 * sin(p) + 0.5, 295 - 128 * cos(p) + 0.5 }'; }
hi=$(px "$TMP/lop.png" "$(at $((rot + 15)))"); lo=$(px "$TMP/lop.png" "$(at $((rot + 195)))")
check "lopsided sensor at rotation $rot: 0.65 of its peak toward its azimuth 15 is warm ($hi)" warm "$hi"
check "and 0.09 toward 195 is blue ($lo)" blue "$lo"
done_testing
