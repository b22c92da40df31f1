#!/bin/sh
# SPDX-License-Identifier: ISC
# check: long
# Pictures to look at: pspng, mksens's PNG and overlay, psshare.  The PNGs
# are read by a decoder of our own (tests/system/peers/pngpeer.py: zlib and
# struct) and checked by pngcheck; pixel values are stated from the curves'
# and the palette's documented definitions (pspng(1)), not from the code.
. "$(dirname "$0")/lib.sh"
for p in pspng mksens psshare psens; do [ -x "$BIN/$p" ] || skip_all "$p not built"; done
command -v python3 >/dev/null || skip_all "python3 missing"
PEER="python3 tests/system/peers/pngpeer.py"
SEN=config/example/ofb/sensors/cosine.sen
DAY=config/example/ofb/img/day_0318_sensor_256.hdr
have_pngcheck=0
command -v pngcheck >/dev/null && have_pngcheck=1
pngok() {   # pngok FILE: pngcheck's verdict, or a skip
	if [ "$have_pngcheck" = 1 ]; then
		check "pngcheck: $(pngcheck "$1" 2>&1 | head -n 1)" pngcheck -q "$1"
	else
		skip "pngcheck not installed"
	fi
}

# ---- pspng: a uniform grey picture, (128 + 0.5) 2^(127 - 136) = 0.2509765625 ----
$PEER flat "$TMP/grey.hdr" 20 10 128 128 128 127
while read -r tone exp want chunk; do
	"$BIN/pspng" -q -e "$exp" -t "$tone" -o "$TMP/g.png" "$TMP/grey.hdr"
	got=$($PEER uniq "$TMP/g.png" 0 0 20 10)
	check "pspng -t $tone -e $exp: every pixel $want $want $want (got '$got')" test "$got" = "$want $want $want"
	check "pspng -t $tone: the PNG carries $chunk" sh -c "$PEER info '$TMP/g.png' | head -n 1 | grep -q ' $chunk '"
done <<'CASES'
linear 1 64 gAMA
linear +1 128 gAMA
linear 4 255 gAMA
srgb 1 137 sRGB
gamma 1 136 gAMA
reinhard auto 255 sRGB
linear auto 46 gAMA
CASES
check "pspng -t linear says gamma 1.0 (gAMA 100000)" sh -c "$PEER info '$TMP/g.png' >/dev/null; \
	'$BIN/pspng' -q -t linear -e 1 -o '$TMP/l.png' '$TMP/grey.hdr' && $PEER info '$TMP/l.png' | grep -q '^(gAMA): 100000$'"
pngok "$TMP/g.png"

# ---- false colour: known luminances get the documented palette's colours ----
# six grey pixels, luminance 179 x 0.2509765625 x 2^k (k = 0..5): 44.9 .. 1437.6 cd/m2
$PEER stripes "$TMP/stripes.hdr" 127 6
"$BIN/pspng" -q -F -s 1500 -z 10 -o "$TMP/f.png" "$TMP/stripes.hdr"
pngok "$TMP/f.png"
k=0
while [ $k -lt 6 ]; do
	got=$($PEER pixel "$TMP/f.png" $((k * 10 + 5)) 5)
	# the palette of pspng(1): anchors at 0 .15 .30 .45 .60 .75 .88 1, linear between
	want=$(python3 - "$k" <<'PY'
import sys
at = [0, .15, .30, .45, .60, .75, .88, 1]
rgb = [(.05, .03, .22), (.16, .10, .55), (.10, .35, .80), (.05, .62, .68),
       (.35, .78, .30), (.85, .80, .15), (.98, .55, .10), (.90, .12, .10)]
k = int(sys.argv[1])
f = 179 * 0.2509765625 * 2 ** k / 1500
i = max(j for j in range(7) if at[j] <= f)
t = (f - at[i]) / (at[i + 1] - at[i])
print(*[int(255 * (a + t * (b - a)) + 0.5) for a, b in zip(rgb[i], rgb[i + 1])])
PY
)
	check "false colour of $(awk -v k=$k 'BEGIN { printf "%.1f", 179 * 0.2509765625 * 2 ^ k }') cd/m2 on a 1500 scale: $want (got $got)" test "$got" = "$want"
	k=$((k + 1))
done
"$BIN/pspng" -q -F -l -o "$TMP/fl.png" "$DAY"
pngok "$TMP/fl.png"
check "pspng -F writes what produced it in its text" sh -c "$PEER info '$TMP/fl.png' | grep -q '^Comment: false colour, log scale 2.5 to 2500 cd/m2 (auto), largest 2456 cd/m2'"

# ---- the tools refuse to write a picture to a terminal ----
if command -v script >/dev/null; then
	script -qec "$BIN/mksens $SEN" /dev/null > "$TMP/tty.out" 2>&1
	rc=$?
	check "mksens to a terminal: exit 2 ($rc)" test "$rc" = 2
	check "mksens to a terminal says to redirect or use --output" grep -q "redirect it (mksens sensor.sen > sensor.hdr) or name a file with --output FILE" "$TMP/tty.out"
	check "mksens wrote no binary to the terminal" sh -c "! grep -q RADIANCE '$TMP/tty.out'"
	script -qec "$BIN/pspng $DAY" /dev/null > "$TMP/tty.out" 2>&1
	check "pspng to a terminal: refused" grep -q "standard output is a terminal" "$TMP/tty.out"
else
	skip "script (util-linux) missing: no terminal to test with"
fi

# ---- mksens: the Radiance picture (unchanged), its PNG, the overlay ----
# each pixel is the sensitivity averaged over its footprint over the peak: psens
# with the uniform sensor integrates it to the cosine's integral over its peak, pi
out=$("$BIN/mksens" -S 256 "$SEN" | "$BIN/psens" -q -s builtin:uniform /dev/stdin)
got=$(printf '%s\n' "$out" | sed 's/.*Response: //')
check "mksens picture integrates to pi within 0.1 % ($got)" \
	awk -v g="$got" 'BEGIN { d = (g - 3.14159265) / 3.14159265; if (d < 0) d = -d; exit !(d < 1e-3) }'
"$BIN/mksens" --resolution 64 --rotation 30 --reading cell "$SEN" > "$TMP/long.hdr"
"$BIN/mksens" -S 64 --rotation 30 -m cell "$SEN" > "$TMP/short.hdr"
check "mksens long options give the short ones' picture" cmp -s "$TMP/long.hdr" "$TMP/short.hdr"
check "mksens header keeps its command line" grep -q "^mksens -S 64 --rotation 30 -m cell " "$TMP/short.hdr"
"$BIN/mksens" -S 200 --rotation 30 -o "$TMP/s.png" "$SEN"
pngok "$TMP/s.png"
# 200 px at zoom 3 (the smallest making 512 px or more), text of 13 px:
# margins of 3 x 13 px, 2 below for the caption, the legend strip 8.5 x 13 + 8
check "mksens PNG: 200 px at zoom 3, margins and legend: 796 x 717 ($($PEER info "$TMP/s.png" | head -n 1 | cut -d' ' -f1,2))" \
	sh -c "$PEER info '$TMP/s.png' | head -n 1 | grep -q '^796 717 '"
# 1 degree from the centre the cosine is 0.9998 of the peak: the palette's
# top, (0.90 0.12 0.10) -> 230 31 26, within a level
got=$($PEER pixel "$TMP/s.png" 342 342)
check "mksens PNG: the peak's colour near the centre ($got)" \
	awk -v g="$got" 'BEGIN { split(g, c, " "); split("230 31 26", w, " "); for (i = 1; i <= 3; i++) { d = c[i] - w[i]; if (d < -1 || d > 1) exit 1 } }'
"$BIN/mksens" --overlay "$DAY" --output "$TMP/o.png" "$SEN"
pngok "$TMP/o.png"
"$BIN/mksens" --overlay "$DAY" --format hdr "$SEN" > /dev/null 2>"$TMP/err"
check "mksens --overlay with --format hdr refused: $(cat "$TMP/err")" grep -q "draws a PNG" "$TMP/err"
"$BIN/mksens" --levels 10,x "$SEN" > /dev/null 2>"$TMP/err"
check "mksens --levels 10,x refused (exit 2)" grep -q "not a list of up to 16 percentages" "$TMP/err"
"$BIN/mksens" --overlay "$SEN" --output "$TMP/x.png" "$SEN" 2>"$TMP/err"
check "mksens --overlay of a non-picture names it: $(cat "$TMP/err")" grep -q "cosine.sen" "$TMP/err"

# ---- psshare ----
"$BIN/psshare" -s "$SEN" --geometry config/example/ofb/radiance/room.rad \
	--geometry config/example/ofb/radiance/lum_off.rad -o "$TMP/share.png" --hdr "$TMP/share.hdr" "$DAY" > "$TMP/share.txt"
diag "$(cat "$TMP/share.txt")"
check "psshare: the regions' shares total 100.00 %" grep -qE '^\(total\) +100\.00 ' "$TMP/share.txt"
check "psshare: the window leads" grep -q '^top: window ' "$TMP/share.txt"
resp=$("$BIN/psens" -q -s "$SEN" "$DAY" | sed 's/.*Response: //')
check "psshare's response is psens's ($resp)" grep -q "^response $resp " "$TMP/share.txt"
sum=$($PEER hdrsum "$TMP/share.hdr")
check "the share picture's pixels add up to 100 % within the RGBE precision ($sum)" \
	awk -v s="$sum" 'BEGIN { d = s - 100; if (d < 0) d = -d; exit !(d < 0.1) }'
pngok "$TMP/share.png"
"$BIN/psshare" -s "$SEN" "$DAY" > "$TMP/sect.txt"
check "psshare without geometry: angular sectors, said so" grep -q "no geometry given (--geometry): angular sectors" "$TMP/sect.txt"
check "psshare sectors total 100.00 %" grep -qE '^\(total\) +100\.00 ' "$TMP/sect.txt"
printf 'm polygon a 0 0 9 0 0 0 1 0 0 0 1 0\n\nm sphere ball 0 0 4 1 1 1 .5\n' > "$TMP/bad.rad"
"$BIN/psshare" -s "$SEN" --geometry "$TMP/bad.rad" "$DAY" > /dev/null 2>"$TMP/err"
rc=$?
check "psshare: a sphere is refused with file:line (exit $rc): $(cat "$TMP/err")" grep -q "bad.rad:3: sphere 'ball' is not handled" "$TMP/err"

# ---- every new program: --help, -V, a bad option ----
for p in pspng mksens psshare; do
	check "$p --help exits 0 with a usage" sh -c "'$BIN/$p' --help | grep -q '^usage: $p'"
	check "$p -V prints its version" sh -c "'$BIN/$p' -V | grep -q '^$p (psensd) '"
	"$BIN/$p" --bogus >/dev/null 2>&1
	check "$p --bogus exits 2" test $? = 2
done
done_testing
