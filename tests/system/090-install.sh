#!/bin/sh
# SPDX-License-Identifier: ISC
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

# make uninstall removes exactly what make install put there: a file that was
# there before stays, an edited configuration stays (and is said to), and the
# tree holds the files it held before the install
u="$TMP/u"
mkdir -p "$u/usr/bin" "$u/etc"
echo mine > "$u/usr/bin/other"; echo mine > "$u/etc/other.conf"
(cd "$u" && find . -type f | sort) > "$TMP/before"
make -s BUILD="$BUILD" install PREFIX=/usr DESTDIR="$u" > "$TMP/log" 2>&1
n=$(cd "$u" && find . -type f | wc -l)
check "make install PREFIX=/usr DESTDIR: $n files" test "$n" -gt 50
make -s BUILD="$BUILD" uninstall PREFIX=/usr DESTDIR="$u" > "$TMP/ulog" 2>&1; rc=$?
(cd "$u" && find . -type f | sort) > "$TMP/after"
check "make uninstall succeeds ($rc) and leaves exactly the files that were there before ($(wc -l < "$TMP/after") files: $(tr '\n' ' ' < "$TMP/after"))" \
	sh -c "[ $rc = 0 ] && cmp -s '$TMP/before' '$TMP/after'"
check "make uninstall removes the psensd directories it made (etc/psensd, usr/share/psensd, var/lib/psensd)" \
	sh -c "[ ! -e '$u/etc/psensd' ] && [ ! -e '$u/usr/share/psensd' ] && [ ! -e '$u/var/lib/psensd' ]"
check "make uninstall keeps the shared directories (usr/bin)" test -d "$u/usr/bin"
make -s BUILD="$BUILD" install DESTDIR="$u" > "$TMP/log" 2>&1
echo "period = 30" >> "$u/etc/psensd/psensd.conf"
make -s BUILD="$BUILD" uninstall DESTDIR="$u" > "$TMP/ulog" 2>&1
check "an edited configuration is kept: $(cat "$TMP/ulog")" \
	sh -c "grep -q 'period = 30' '$u/etc/psensd/psensd.conf' && grep -q 'psensd.conf was edited: kept' '$TMP/ulog'"
check "everything else of the default PREFIX (/usr/local) is gone" \
	sh -c "[ -z \"\$(find '$u/usr/local' -type f 2>/dev/null)\" ]"
done_testing
