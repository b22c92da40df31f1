#!/bin/sh
# SPDX-License-Identifier: ISC
# psensctl report: the commissioning record of a real simulated day (psensd
# -s on the example configuration) as a document: PDF read back by
# pdftotext (poppler), PNG checked by pngcheck, SVG by xmllint; no two
# texts overlap on any page (the boxes the drawing code records, checked
# here by awk); a misspelled zone is an error naming the zones, exit 1 and
# no file; a failed report leaves no file and an older report untouched.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] && [ -x "$BIN/psensctl" ] || skip_all "psensd not built"
mkdir -p "$TMP/example" "$TMP/state"
cp -R config/example/ofb config/example/ofb.scene "$TMP/example/"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db|" config/psensd.conf > "$TMP/psensd.conf"
PATH="$TOP/$BIN:$PATH" "$BIN/psensd" -f "$TMP/psensd.conf" -s > "$TMP/day.out" 2> "$TMP/day.err"
check "psensd ran the simulated day" test "$(sqlite3 "$TMP/state/psensd.db" 'select count(*) from samples')" -gt 0
R() { "$BIN/psensctl" -d "$TMP/state/psensd.db" report "$@"; }
SITE="Validation office, Lab 2"
R office -c "$TMP/psensd.conf" --site "$SITE" -o "$TMP/r.pdf" --boxes "$TMP/boxes" > "$TMP/r.out" 2> "$TMP/r.err"
check "report -o r.pdf exits 0 and says the verdict: $(cat "$TMP/r.out" "$TMP/r.err")" grep -q "r.pdf: zone office: not calibrated" "$TMP/r.out"
check "it is a PDF" sh -c "head -c 5 '$TMP/r.pdf' | grep -q '%PDF-'"
if command -v pdftotext > /dev/null; then
	pdftotext -layout "$TMP/r.pdf" "$TMP/r.txt"
	has() { grep -qF -- "$1" "$TMP/r.txt"; }
	check "pdfinfo: 2 pages" test "$(pdfinfo "$TMP/r.pdf" | awk '/^Pages:/ { print $2 }')" = 2
	check "pdfinfo: title and subject (the site)" sh -c "pdfinfo '$TMP/r.pdf' | grep -q '^Title: *psensd commissioning record' && pdfinfo '$TMP/r.pdf' | grep -q '^Subject: *$SITE'"
	check "the title" has "ommissioning record"
	check "the site" has "$SITE"
	check "the zone and its sensor" has "point room.sensor, device room (loopback)"
	check "the configuration's SHA-256 (sha256sum)" has "$(sha256sum "$TMP/psensd.conf" | cut -c1-64)"
	check "the scene's SHA-256 (psscene's, from the results file)" has "$(awk '$1 == "scene_hash" { print $3; exit }' "$TMP/state/ofb.results")"
	check "the simulated date" has "the room's day 03-18"
	check "the record's span, dated" grep -Eq "[0-9]{4}-03-18 06:00 to [0-9]{4}-03-18 19:59 \(14.0 h, local time\)" "$TMP/r.txt"
	check "the date it was written (UTC)" has "$(date -u +%Y-%m-%d)"
	check "the verdict" has "NOT CALIBRATED"
	# the loopback room is a simulation: the record says so on every page,
	# names the span as simulated, and has no sign-off block to sign
	check "no sign-off block: the simulated devices stated instead" sh -c "grep -q 'SIMULATED: no sign-off' '$TMP/r.txt' && grep -q 'zone office: the zone.s devices are simulated (loopback)' '$TMP/r.txt' && ! grep -q 'Signature' '$TMP/r.txt'"
	check "every page (2) says SIMULATED" test "$(grep -c "SIMULATED . not a building's record" "$TMP/r.txt")" = 2
	check "the title says SIMULATED" has "SIMULATED commissioning record"
	check "the span is named as simulated" grep -q "Simulated records *[0-9]\{4\}-03-18 06:00 to" "$TMP/r.txt"
	check "the target" has "target 500 lx"
	# pdftotext puts each word of a turned (y axis) title on a line of its own
	pdftotext -raw "$TMP/r.pdf" - | tr '\n' ' ' > "$TMP/r.raw"
	check "the axis titles with units" sh -c "for t in 'sensor signal (V)' 'task illuminance (lx)' 'light output (%)' 'energy (full-load h)' 'local time of day (hh:mm)'; do grep -qF \"\$t\" '$TMP/r.raw' || exit 1; done"
	check "a day with no midnight on its axes says nothing of a dashed midnight line" \
		sh -c "! grep -q 'dashed line is midnight' '$TMP/r.raw'"
	check "round time ticks (every 2 h)" sh -c "grep -q '06:00 *08:00 *10:00 *12:00 *14:00 *16:00 *18:00' '$TMP/r.txt'"
	check "no odd ticks (09:29 or 0.934)" sh -c "! grep -qE '09:29|0\\.934|1\\.87' '$TMP/r.txt'"
	check "the faults: 20 min at the safe level" has "faults 20 min"
else
	skip "pdftotext not installed (poppler-utils): the PDF's text is not checked"
fi
# the texts' boxes, checked apart from the code that drew them
check "boxes recorded for both pages" test "$(awk '{ print $1 }' "$TMP/boxes" | sort -u | wc -l)" = 2
awk '{ p[NR] = $1; x0[NR] = $2; y0[NR] = $3; x1[NR] = $4; y1[NR] = $5; $1 = $2 = $3 = $4 = $5 = ""; t[NR] = $0 }
     END { for (i = 1; i <= NR; i++) for (j = i + 1; j <= NR; j++)
               if (p[i] == p[j] && (x1[i] < x1[j] ? x1[i] : x1[j]) - (x0[i] > x0[j] ? x0[i] : x0[j]) > 0.01 &&
                   (y1[i] < y1[j] ? y1[i] : y1[j]) - (y0[i] > y0[j] ? y0[i] : y0[j]) > 0.01)
                   print "page " p[i] ":" t[i] " overlaps" t[j] }' "$TMP/boxes" > "$TMP/overlaps"
check "no two texts overlap on any page ($(wc -l < "$TMP/boxes") boxes): $(head -n 2 "$TMP/overlaps")" test ! -s "$TMP/overlaps"
check "every page's content (not its footer) reaches 85 % down: no half-empty page" \
	awk '$3 < 800 { if ($5 > b[$1]) b[$1] = $5 } END { for (p in b) if (b[p] < 0.85 * 841.89) exit 1 }' "$TMP/boxes"
# nor an empty band: the largest vertical gap between texts (a chart's
# tick labels count) under 15 % of the page; without the cover's chart of
# every zone's output it is 226 pt (27 %), with it 28 pt
awk '$3 < 800 { n[$1]++; y0[$1, n[$1]] = $3; y1[$1, n[$1]] = $5 }
     END { worst = 0
           for (p in n) { m = n[p]
               for (i = 1; i <= m; i++) { a[i] = y0[p, i]; b[i] = y1[p, i] }
               for (i = 2; i <= m; i++) { ka = a[i]; kb = b[i]; j = i - 1
                   while (j > 0 && a[j] > ka) { a[j + 1] = a[j]; b[j + 1] = b[j]; j-- }
                   a[j + 1] = ka; b[j + 1] = kb }
               reach = b[1]
               for (i = 2; i <= m; i++) { if (a[i] - reach > worst) worst = a[i] - reach; if (b[i] > reach) reach = b[i] } }
           printf "%.0f\n", worst }' "$TMP/boxes" > "$TMP/gap"
check "no empty band: the largest gap between texts is $(cat "$TMP/gap") pt (< 126, 15 % of the page)" \
	test "$(cat "$TMP/gap")" -lt 126
# PNG and SVG
R office -c "$TMP/psensd.conf" -o "$TMP/r.png" > /dev/null 2> "$TMP/png.err"; rc=$?
check "-o r.png exits 0: $(head -c 200 "$TMP/png.err")" test "$rc" = 0
if command -v pngcheck > /dev/null; then
	check "the PNG passes pngcheck: $(pngcheck "$TMP/r.png" 2>&1 | cut -c1-90)" pngcheck -q "$TMP/r.png"
else
	skip "pngcheck not installed"
fi
check "the PNG holds both pages at 1.5 px/pt (893 x 2544)" sh -c "pngcheck '$TMP/r.png' | grep -q '893x2544'"
R office --page 1 -o "$TMP/p1.png" > /dev/null
check "--page 1: the cover alone (893 x 1263)" sh -c "pngcheck '$TMP/p1.png' | grep -q '893x1263'"
R office --format svg -o "$TMP/r.out.svg" > /dev/null 2> "$TMP/svg.err"; rc=$?
check "--format svg exits 0: $(head -c 200 "$TMP/svg.err")" test "$rc" = 0
if command -v xmllint > /dev/null; then
	check "the SVG is well-formed XML (xmllint)" xmllint --noout "$TMP/r.out.svg"
else
	skip "xmllint not installed"
fi
if command -v rsvg-convert > /dev/null; then
	rsvg-convert -o "$TMP/svg.png" "$TMP/r.out.svg" 2> "$TMP/rsvg.err"
	check "librsvg renders the SVG: two A4 pages and the gap at 96 dpi (794 x 2262): $(pngcheck "$TMP/svg.png" 2>&1 | cut -c1-80)" \
		sh -c "pngcheck '$TMP/svg.png' | grep -q '794x2262'"
else
	skip "rsvg-convert not installed (librsvg2-bin)"
fi
R office > "$TMP/stdout.pdf"
check "without -o the PDF goes to standard output" sh -c "head -c 5 '$TMP/stdout.pdf' | grep -q '%PDF-'"
# errors: a misspelled zone
R ofice -o "$TMP/bad.pdf" > "$TMP/bad.out" 2> "$TMP/bad.err"; rc=$?
check "a misspelled zone exits 1: $(cat "$TMP/bad.err")" test "$rc" = 1
check "and names the zone and the zones there are" grep -q "no zone 'ofice' (zones: office)" "$TMP/bad.err"
check "and writes no file" test ! -e "$TMP/bad.pdf"
# a failed report leaves no file, and an older report untouched
"$BIN/psensctl" -d "$TMP/nonexistent.db" report office -o "$TMP/none.pdf" 2> "$TMP/none.err"; rc=$?
check "a missing database: exit 1, named: $(cat "$TMP/none.err")" sh -c "test $rc = 1 && grep -q nonexistent.db '$TMP/none.err'"
check "and no 0-byte file" test ! -e "$TMP/none.pdf"
cp "$TMP/r.pdf" "$TMP/keep.pdf"
R ofice -o "$TMP/r.pdf" 2> /dev/null
check "a failed report leaves the older one as it was" cmp -s "$TMP/r.pdf" "$TMP/keep.pdf"
check "and no temporary file behind" test -z "$(ls -A "$TMP" | grep '^\.')"
R office -o "$TMP/no/such/dir/r.pdf" 2> "$TMP/dir.err"; rc=$?
check "an output directory that does not exist: exit 1, the path named: $(cat "$TMP/dir.err")" \
	sh -c "test $rc = 1 && grep -q 'no/such/dir/r.pdf: No such file or directory' '$TMP/dir.err'"
R office -o "$TMP/r.txt" > /dev/null 2> "$TMP/ext.err"; rc=$?
check "an unknown extension without --format: exit 2, said" sh -c "test $rc = 2 && grep -q 'pdf, .png or .svg' '$TMP/ext.err'"
# asking a running psensd: its database and its configuration (an absolute path)
sed "s|^database = .*|database = $TMP/state/psensd.db|; s|^results = .*|results = $TMP/state/ofb.results|; /^\[psensd\]/a socket = $TMP/sock" "$TMP/psensd.conf" > "$TMP/live.conf"
"$BIN/psensd" -f "$TMP/live.conf" -t 12:30 -x 60 > "$TMP/live.out" 2> "$TMP/live.err" &
PID=$!; track_pid $PID
if wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/sock\" ping > /dev/null"; then
	"$BIN/psensctl" -s "$TMP/sock" report office -o "$TMP/live.pdf" > "$TMP/live.rep" 2>&1; rc=$?
	check "report through the socket exits 0: $(cat "$TMP/live.rep")" test "$rc" = 0
	if command -v pdftotext > /dev/null; then
		check "and takes psensd's configuration: its path and SHA-256" sh -c "pdftotext -layout '$TMP/live.pdf' - | grep -q '$TMP/live.conf' && pdftotext -layout '$TMP/live.pdf' - | grep -q \"\$(sha256sum '$TMP/live.conf' | cut -c1-64)\""
	fi
	kill -TERM $PID; wait $PID 2>/dev/null
else
	not_ok "psensd did not answer on its socket: $(tail -n 3 "$TMP/live.err")"
fi
done_testing
