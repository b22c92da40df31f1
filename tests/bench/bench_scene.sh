#!/bin/sh
# SPDX-License-Identifier: ISC
# Scene precompute: the example scene cold (empty cache) and warm, and the
# error against run time of the validation office's renders (bounces and
# resolution against the converged reference).
BIN=${BIN:-${BUILD:-build}/bin}
tmp=$(mktemp -d /tmp/psbench.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
t() { s=$(date +%s.%N); "$@" > /dev/null 2>&1 || echo "FAILED: $*"; e=$(date +%s.%N); awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", b - a }'; }
cold=$(t "$BIN/psscene" -q -C "$tmp/cache" -o "$tmp/r" config/example/ofb.scene)
warm=$(t "$BIN/psscene" -q -C "$tmp/cache" -o "$tmp/r" config/example/ofb.scene)
echo "psscene on the example scene (8 pictures of 256 x 256): cold $cold s, warm $warm s"
echo
"$BIN/psscene" -N -o "$tmp/c" tests/data/ofb/convergence.scene | sed -n '/^renders of/,/^$/p'
echo "(render s: the fixtures' rpict times, sensor + task; the rest computed here)"
