#!/bin/sh
# SPDX-License-Identifier: ISC
# psscene with the task as a work-plane grid ([daylight_coefficients]
# task_matrix, an rfluxmtx -I+ matrix) instead of the task's pictures: the
# example office's point under the sensor (row 2 of
# config/example/ofb/dc/points_mf1.mtx, the point route) gives the year's
# mean task/sensor ratio within 2.5 % of the picture route's (both are
# Monte Carlo estimates by different paths: measured +1.58 %); the mean of
# two rows is the mean of the rows' years (the task is linear in the rows);
# a row the grid lacks, and a grid beside task pictures, are refused
# naming the file and line.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psscene" ] || skip_all "psscene not built"
BIN=$(cd "$BIN" && pwd)
mkdir -p "$TMP/ex"
cp -R "$TOP/config/example/ofb" "$TOP/config/example/ofb.scene" "$TMP/ex/"
cd "$TMP/ex" || exit 1
grid() { sed "s|^task_pictures = .*|task_matrix = ofb/dc/points_mf1.mtx\n$1|; /^task_view = /d" ofb.scene; }
ratio() { sed -n 's/^mean_ratio = //p' "$1"; }
"$BIN/psscene" -q -N -o pic.results ofb.scene > /dev/null 2>&1
check "the picture route runs" test -s pic.results
grid "task_points = 2" > g2.scene
"$BIN/psscene" -q -N -o g2.results g2.scene > /dev/null 2> err
check "the grid route runs" test -s g2.results
p=$(ratio pic.results); g=$(ratio g2.results)
check "the year's mean ratio: grid $g against pictures $p, within 2.5 %" \
	awk -v p="$p" -v g="$g" 'BEGIN { d = g / p - 1; if (d < 0) d = -d; exit !(p > 0 && d < 0.025) }'
# the mean of rows 1 and 2 against the two rows' own years: the task lux of each hour is the mean
grid "task_points = 1" > g1.scene
grid "task_points = 1,2" > g12.scene
"$BIN/psscene" -q -N -o g1.results g1.scene > /dev/null 2>&1
"$BIN/psscene" -q -N -o g12.results g12.scene > /dev/null 2>&1
check "each hour's task lux of rows 1,2 is the mean of row 1's and row 2's" python3 -c "
import sys
def hours(f):
    return [float(l.split()[6]) for l in open(f) if l.startswith('h') and ' = ' in l and l.split()[0][1:].isdigit()]
a, b, m = hours('g1.results'), hours('g2.results'), hours('g12.results')
sys.exit(not (len(m) > 4000 and len(a) == len(m) == len(b) and
              all(abs(x - (y + z) / 2) <= 1e-9 * max(1.0, x) for x, y, z in zip(m, a, b))))"
grid "task_points = 3" > g3.scene
"$BIN/psscene" -q -N -o g3.results g3.scene > /dev/null 2> err
check "a row the grid lacks refused" grep -q "points_mf1.mtx: task_points names row 3 of 2" err
sed 's|^task_pictures = \(.*\)|task_pictures = \1\ntask_matrix = ofb/dc/points_mf1.mtx|' ofb.scene > both.scene
"$BIN/psscene" -q -N -o both.results both.scene > /dev/null 2> err
check "a grid beside task pictures refused, naming the line" grep -q "both.scene:[0-9]*: task_matrix: the task is a grid or pictures" err
done_testing
