#!/bin/sh
# SPDX-License-Identifier: ISC
# The installed unit: Type=notify with a watchdog, state and runtime
# directories, ordered after time-sync.target (the log's dates need a
# synchronised wall clock), and a sandbox whose exposure (systemd-analyze security
# --offline=true) is at most 2.0.  The exposure is printed for CI's log.
. "$(dirname "$0")/lib.sh"
command -v systemd-analyze > /dev/null || skip_all "systemd-analyze not installed"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
d="$TMP/dest"
make -s BUILD="$BUILD" install PREFIX=/usr DESTDIR="$d" > "$TMP/log" 2>&1
u="$d/lib/systemd/system/psensd.service"
check "the unit is installed" test -f "$u"
check "the sysusers file and the udev rules are installed" \
	test -f "$d/usr/lib/sysusers.d/psensd.conf" -a -f "$d/usr/lib/udev/rules.d/60-psensd.rules"
check "ExecStart names the installed psensd" grep -q "^ExecStart=/usr/sbin/psensd -f /etc/psensd/psensd.conf$" "$u"
for k in Type=notify WatchdogSec= Restart=on-failure StateDirectory=psensd RuntimeDirectory=psensd \
	"SupplementaryGroups=dialout plugdev gpio"; do
	check "the unit sets $k" grep -q "^$k" "$u"
done
# the log's dates follow the wall clock: start after it is synchronised
check "the unit is ordered after time-sync.target (After=)" grep -q "^After=.*\<time-sync\.target\>" "$u"
check "and pulls it in (Wants=)" grep -q "^Wants=.*\<time-sync\.target\>" "$u"
systemd-analyze security --offline=true "$u" > "$TMP/sec" 2>&1
e=$(sed -n 's/.*Overall exposure level for psensd.service: \([0-9.]*\).*/\1/p' "$TMP/sec")
diag "systemd-analyze security --offline=true: exposure $e"
check "exposure $e is at most 2.0" awk -v e="${e:-99}" 'BEGIN { exit !(e <= 2.0) }'
# the socket the unit's RuntimeDirectory holds is where psensd and psensctl look by default
done_testing
