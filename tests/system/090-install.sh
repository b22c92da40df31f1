#!/bin/sh
# make install into a staging directory: programs, man pages, configuration
# pointed at the installed example, the CIE data; the installed tools run.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] || skip_all "not built"
d="$TMP/dest"
make -s BUILD="$BUILD" install PREFIX=/usr DESTDIR="$d" > "$TMP/log" 2>&1
rc=$?; check "make install succeeds" test "$rc" = 0 || sed "s/^/# /" "$TMP/log"
for f in usr/bin/psens usr/bin/mksens usr/bin/psfilter usr/bin/psscene usr/sbin/psensd \
	usr/bin/pspng usr/bin/psshare usr/share/man/man1/pspng.1 usr/share/man/man1/psshare.1 \
	usr/share/man/man1/psens.1 usr/share/man/man1/psscene.1 usr/share/man/man5/psscene.5 \
	usr/share/man/man5/psensd.conf.5 usr/share/man/man8/psensd.8 etc/psensd/psensd.conf \
	usr/share/psensd/example/ofb.scene usr/share/psensd/cie/LICENSE; do
	check "installed $f" test -e "$d/$f"
done
check "installed config names the installed scene" grep -q "^scene = /usr/share/psensd/example/ofb.scene" "$d/etc/psensd/psensd.conf"
# the installed psscene runs on the installed example (paths rewritten to the staging dir)
sed "s|/usr/share|$d/usr/share|" "$d/etc/psensd/psensd.conf" > "$TMP/p.conf"
"$d/usr/bin/psscene" -q -N -o "$TMP/r" "$d/usr/share/psensd/example/ofb.scene"
check "installed psscene runs on the installed example" test -s "$TMP/r"
done_testing
