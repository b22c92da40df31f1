#!/bin/sh
# SPDX-License-Identifier: ISC
# Real-time psensd on the shipped configuration (no socket key) by a user
# who cannot write /run/psensd: the control socket goes to
# $XDG_RUNTIME_DIR/psensd.sock, and psensctl finds it there with no -s.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
[ -w /run/psensd ] && skip_all "/run/psensd is writable here: the system socket is used"
example_results
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/state/u.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
	config/psensd.conf > "$TMP/psensd.conf"
check "the shipped configuration names no socket" sh -c "! grep -q '^socket' config/psensd.conf"
mkdir -p "$TMP/xdg"; chmod 700 "$TMP/xdg"
env -u RUNTIME_DIRECTORY -u PSENSD_SOCKET XDG_RUNTIME_DIR="$TMP/xdg" \
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pd=$!
track_pid $pd
wait_for 10 test -S "$TMP/xdg/psensd.sock"
check "psensd serves its socket in \$XDG_RUNTIME_DIR: $(grep -i socket "$TMP/err" | head -n 1)" test -S "$TMP/xdg/psensd.sock"
out=$(env -u PSENSD_SOCKET XDG_RUNTIME_DIR="$TMP/xdg" "$BIN/psensctl" ping 2>&1); rc=$?
check "psensctl ping finds it with no -s (exit $rc): $out" test "$rc" = 0
kill -TERM $pd; wait $pd
check "psensd stopped cleanly, the socket removed" test ! -e "$TMP/xdg/psensd.sock"
done_testing
