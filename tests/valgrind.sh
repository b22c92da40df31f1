#!/bin/sh
# SPDX-License-Identifier: ISC
# The daemon's system tests once under valgrind: psensd and psensctl are
# replaced (through $BIN) by wrappers that run the real binaries under
# memcheck with --track-fds, each process logging to its own file.  Then
# every log must show no memory errors, no definite or indirect leaks, and
# no descriptor left open at exit beyond stdin, stdout and stderr.
# Usage: tests/valgrind.sh TEST.sh...   (BUILD, BIN, TOP as for tests/run.sh)
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
TOP=${TOP:-$(pwd)}
command -v valgrind > /dev/null || { echo "valgrind: not installed, skipped"; echo "check: 0 passed, 0 failed, 1 skipped"; exit 0; }
VG=$TOP/$BUILD/valgrind
rm -rf "$VG"; mkdir -p "$VG/bin" "$VG/logs"
chmod 1777 "$VG/logs"   # psensctl also runs as another user in 220
for b in "$TOP/$BIN"/*; do
	name=$(basename "$b")
	case "$name" in
	psensd|psensctl)
		cat > "$VG/bin/$name" <<W
#!/bin/sh
exec valgrind -q --leak-check=full --show-leak-kinds=definite,indirect \\
	--errors-for-leak-kinds=definite,indirect --track-fds=yes --child-silent-after-fork=yes \\
	--suppressions=$TOP/tests/valgrind.supp \\
	--log-file=$VG/logs/$name.%p.log "$b" "\$@"
W
		chmod +x "$VG/bin/$name" ;;
	*) ln -s "$b" "$VG/bin/$name" ;;
	esac
done
BUILD=$BUILD BIN=$VG/bin TOP=$TOP LOGDIR=$VG/test-logs sh "$TOP/tests/run.sh" "$@" | sed '$d'
# the verdict on the valgrind logs
pass=0; fail=0
for l in "$VG"/logs/*.log; do
	[ -e "$l" ] || continue
	# memcheck errors (any "==PID== " line but the descriptor report), and open descriptors
	errs=$(grep -v -e 'FILE DESCRIPTORS' -e 'Open file descriptor [0-9]*:' -e '<inherited from parent>' \
		-e '^==[0-9]*== *$' "$l" | grep -c '^==[0-9]*== ')
	# descriptors psensd opened and left open (inherited ones are the caller's)
	fds=$(awk '/Open file descriptor [0-9]+:/ { if (fd != "") n += !inh; fd = $0; inh = 0; next }
		/<inherited from parent>/ { inh = 1 }
		END { if (fd != "") n += !inh; print n + 0 }' "$l")
	if [ "$errs" = 0 ] && [ "${fds:-0}" -le 0 ]; then
		pass=$((pass + 1))
	else
		fail=$((fail + 1))
		echo "FAIL $(basename "$l"): $errs lines of errors, ${fds:-?} descriptors open beyond std at exit"
		sed 's/^/    /' "$l" | head -n 40
	fi
done
echo "valgrind: $pass process logs clean, $fail not"
echo "check: $pass passed, $fail failed, 0 skipped"
[ "$fail" = 0 ]
