#!/bin/sh
# SPDX-License-Identifier: ISC
# Every walk-through has its files: the shipped configurations with [mqtt]
# (doc/mqtt.md) and [web] (doc/console.md) exist, the docs name them, and
# psensd -n accepts each of them as the docs run them: from the top of a
# source tree, with the build directory beside config/ (the examples keep
# their results and logs in ../../build), the console's password file made
# by psensctl web-passwd as doc/console.md says.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
cd "$TOP" || exit 1
for f in mqtt console; do
	check "config/example/$f.conf is shipped" test -f "config/example/$f.conf"
done
check "doc/mqtt.md runs config/example/mqtt.conf" grep -q 'psensd -f config/example/mqtt.conf' doc/mqtt.md
check "doc/console.md runs config/example/console.conf" \
	grep -q 'psensd -f config/example/console.conf' doc/console.md
check "config/example/mqtt.conf has [mqtt]" grep -q '^\[mqtt\]' config/example/mqtt.conf
check "config/example/console.conf has [web]" grep -q '^\[web\]' config/example/console.conf
B=$(cd "$BIN" && pwd)
# a tree of its own: config/ and an empty build/ beside it
mkdir -p "$TMP/tree/build" && cp -R config "$TMP/tree/"
printf 'a commissioning password\n' | "$B/psensctl" web-passwd "$TMP/tree/build/web.pass" > /dev/null
"$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in" && mq=no || mq=yes
"$BIN/psensd" -h | grep -q "^web: .*not compiled in" && web=no || web=yes
if [ $mq = yes ]; then
	(cd "$TMP/tree" && "$B/psensd" -n -f config/example/mqtt.conf) > "$TMP/mqtt.out" 2>&1
	rc=$?
	check "psensd -n config/example/mqtt.conf: exit 0 ($(tail -n 1 "$TMP/mqtt.out"))" test $rc = 0
else
	skip "psensd built without MQTT"
fi
if [ $web = yes ]; then
	(cd "$TMP/tree" && "$B/psensd" -n -f config/example/console.conf) > "$TMP/console.out" 2>&1
	rc=$?
	check "psensd -n config/example/console.conf: exit 0 ($(tail -n 1 "$TMP/console.out"))" test $rc = 0
else
	skip "psensd built without the console"
fi
done_testing
