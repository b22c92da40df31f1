#!/bin/sh
# SPDX-License-Identifier: ISC
# A warm read of a large cached map (the linear reading of a table that
# changes with azimuth, 4000 x 4000: about 100 MB) releases the mapped entry
# as a whole, not row by row: each madvise(MADV_DONTNEED) on a shared map is
# a TLB shoot-down on every core, and one a row (4000 of them) was most of
# the run's system time.  Counted with strace; the warm numbers must be the
# cold run's.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] || skip_all "psens not built"
command -v strace >/dev/null || skip_all "no strace"
command -v python3 >/dev/null || skip_all "no python3"
strace -f -o /dev/null true 2>/dev/null || skip_all "strace cannot trace here"
# a sanitized psens counts the sanitizer's own madvise calls, and
# LeakSanitizer refuses to run under ptrace
ldd "$BIN/psens" 2>/dev/null | grep -q 'libasan\|libtsan\|libubsan' &&
	skip_all "psens is built with a sanitizer: strace would count the sanitizer's calls"
# a uniform picture, flat (not run-length) RGBE scanlines: 128 128 128 @ 129
python3 - "$TMP/u.hdr" <<'PY'
import sys
n = 4000
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n"
            b"VIEW= -vta -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180\n\n-Y %d +X %d\n" % (n, n))
    f.write(b"\x80\x80\x80\x81" * (n * n))
PY
cat > "$TMP/az.sen" <<'SEN'
Elevation field 90
degrees 0 45 90 135 180 225 270 315
0 1 1 1 1 1 1 1 1
20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9
40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75
60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5
80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1
90 0 0 0 0 0 0 0 0
SEN
run() { "$BIN/psens" -q -C "$TMP/c" -m linear -s "$TMP/az.sen" "$TMP/u.hdr"; }
cold=$(run)
check "cold: exit 0 and a response" test -n "$cold"
big=$(find "$TMP/c/blobs" -type f ! -name .lock -size +64M | wc -l)
check "the entry is a large one, over 64 MiB ($big)" test "$big" = 1
warm=$(strace -f -o "$TMP/st" -c -e trace=madvise "$BIN/psens" -q -C "$TMP/c" -m linear \
	-s "$TMP/az.sen" "$TMP/u.hdr")
check "warm: the cold run's numbers" test "$warm" = "$cold"
# one release for the check of the entry, one after the read; a few more
# (huge-page advice) are allowed, never one a row
# strace -c: % time, seconds, usecs/call, calls, [errors,] syscall
n=$(awk '$NF == "madvise" { print $4 + 0; exit }' "$TMP/st")
diag "warm run: ${n:-0} madvise calls"
check "warm: at most 8 madvise calls (${n:-0})" test "${n:-0}" -le 8
done_testing
