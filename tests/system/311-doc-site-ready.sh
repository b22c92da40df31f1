#!/bin/sh
# SPDX-License-Identifier: ISC
# The site dry run of doc/site.md as written, on a fresh copy of the tree
# (no east-zone simulation computed yet, a ready file left by an earlier run):
# psensd starts only once psvirt is ready, so its first minutes log no fault
# on any zone (psensd started at once logged every zone's connection
# refused).  The port is a free one instead of 1502 (in the copied site.conf
# too) and psensd runs 4 s of the document's 86.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt not built"
BINABS=$(cd "$BIN" && pwd)
mkdir -p "$TMP/top/config" "$TMP/top/build"
cp -R config/example "$TMP/top/config/"
ln -s "$BINABS" "$TMP/top/build/bin"
port=$(free_port)
awk '/^## A site dry run/ { s = 1; next } /^## / { s = 0 }
     s && /^```/ { if (b) exit; b = 1; next }
     s && b && /^\$ / { c = 1; sub(/^\$ /, "") } s && b && c { print; c = /\\$/ }' doc/site.md |
	sed -e "s/1502/$port/g" -e 's/^timeout 86 /timeout 4 /' -e 's/; kill %1$/; kill $!/' -e '/^timeout 4 /q' > "$TMP/site.sh"
sed -i "s/^port = 1502/port = $port/" "$TMP/top/config/example/site.conf"
diag "$(cat "$TMP/site.sh")"
check "the walk-through waits for psvirt's ready file" grep -q '^until \[ -s build/psvirt.ready \]' "$TMP/site.sh"
check "... after removing an earlier run's" grep -q '^rm -f build/psvirt.ready' "$TMP/site.sh"
echo 1 > "$TMP/top/build/psvirt.ready"   # an earlier run's
# psvirt started in the script is killed by it (kill $!); the whole group is ended after
(cd "$TMP/top" && setsid sh -c '. "$1"' sh "$TMP/site.sh") > "$TMP/out" 2> "$TMP/err" &
W=$!
i=0; while kill -0 $W 2>/dev/null && [ $i -lt 600 ]; do sleep 0.1; i=$((i + 1)); done
kill -TERM -- -$W 2>/dev/null
diag "$(grep -v '^#' "$TMP/err" | head -n 12)"
check "psensd ran" grep -q "controlling 3 zone(s) from config/example/site.conf" "$TMP/err"
check "no zone's connection refused or any fault: $(grep -m 1 -i 'fault\|refused' "$TMP/err")" \
	sh -c "! grep -qi 'fault:\|refused' '$TMP/err'"
done_testing
